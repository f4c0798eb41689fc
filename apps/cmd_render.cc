// spritestation render SEQ.json --out OUT: play optimized sequences back through the
// virtual camera (seed 000 §6) into a video (.mkv, .mp4) or a folder of PNG frames with alpha.
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>

#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "animate/playback.h"
#include "animate/sequence_io.h"
#include "animate/spec.h"
#include "apps/commands.h"
#include "capture/recording/video_file.h"
#include "core/error.h"
#include "core/log.h"

namespace ss::apps {
namespace {

namespace fs = std::filesystem;

struct RenderArgs {
  std::string sequences;
  std::string out;
  std::string spec;
  std::string codec = "h264";
  bool stages = false;
  bool no_shadows = false;
  bool json = false;
};

// Frames go to a video (.mkv, .mp4: animate/video_file.h) or to numbered PNGs with alpha in
// a folder.
class FrameSink {
 public:
  FrameSink(const std::string& out, int width, int height, double fps, const std::string& codec) {
    if (IsVideoPath(out)) {
      video_ = std::make_unique<VideoFileWriter>(out, width, height, fps, codec);
    } else {
      if (fs::path(out).has_extension()) {
        throw InputError(out, "expected a .mkv or .mp4 file, or a folder for PNG frames");
      }
      fs::create_directories(out);
      folder_ = out;
    }
  }
  void Write(const cv::Mat& bgra) {
    if (video_) {
      video_->Write(bgra);  // transparent parts become black
    } else {
      char name[32];
      std::snprintf(name, sizeof name, "frame_%06d.png", frames_);
      const std::string path = (fs::path(folder_) / name).string();
      if (!cv::imwrite(path, bgra)) throw WorkError(path, "cannot write the frame");
    }
    ++frames_;
  }
  void Close() {
    if (video_) video_->Close();
  }
  int frames() const { return frames_; }
  std::string encoder() const { return video_ ? video_->encoder_name() : "png"; }

 private:
  std::unique_ptr<VideoFileWriter> video_;
  std::string folder_;
  int frames_ = 0;
};

void Run(const RenderArgs& args) {
  const SequenceFile file = ReadSequenceFile(args.sequences);
  std::string background_path = file.background_path;
  std::optional<CameraModel> from_spec;
  if (!args.spec.empty()) {
    const AnimationSpec spec = LoadAnimationSpec(args.spec);
    from_spec = ReadSpecCamera(spec);  // as `animate` reads it
    background_path = spec.background_path;
  }
  const CameraModel camera = from_spec ? *from_spec : CameraModel::Read(file.camera_path);
  cv::Mat background;
  if (!background_path.empty()) {
    background = cv::imread(background_path, cv::IMREAD_UNCHANGED);
    if (background.empty()) throw InputError(background_path, "cannot read the background image");
  }
  RenderOptions render_options;
  render_options.shadows = !args.no_shadows;
  SequencePlayer player(file.bank_paths,
                        std::make_unique<SpriteRenderer>(camera, background, render_options));
  FrameSink sink(args.out, camera.width(), camera.height(), file.frame_rate, args.codec);

  std::vector<const SequenceStage*> stages;
  if (args.stages) {
    for (const SequenceStage& s : file.stages) stages.push_back(&s);
  }
  auto play = [&](const std::vector<SpriteSequence>& sprites, const std::string& caption) {
    const int steps = LongestSequence(sprites);
    for (int t = 0; t < steps; ++t) {
      cv::Mat frame = player.RenderStep(sprites, t);
      if (!caption.empty()) {
        cv::putText(frame, caption, {12, 28}, cv::FONT_HERSHEY_SIMPLEX, 0.7,
                    cv::Scalar(255, 255, 255, 255), 2, cv::LINE_AA);
      }
      sink.Write(frame);
    }
  };
  char caption[96];
  for (const SequenceStage* s : stages) {
    std::snprintf(caption, sizeof caption, "after %.0f s: cost %.4g", s->seconds, s->cost);
    play(s->sprites, caption);
  }
  play(file.sprites, stages.empty() ? "" : "final");
  sink.Close();

  if (args.json) {
    const nlohmann::json j = {{"out", args.out},           {"frames", sink.frames()},
                              {"encoder", sink.encoder()}, {"width", camera.width()},
                              {"height", camera.height()}, {"frame_rate", file.frame_rate},
                              {"stages", stages.size()}};
    std::printf("%s\n", j.dump(2).c_str());
  } else {
    std::printf("rendered %d frames (%dx%d, %.3g fps%s) to %s\n", sink.frames(), camera.width(),
                camera.height(), file.frame_rate,
                stages.empty() ? "" : (", " + std::to_string(stages.size()) + " stages").c_str(),
                args.out.c_str());
  }
}

}  // namespace

void AddRenderCommand(CLI::App& app) {
  auto args = std::make_shared<RenderArgs>();
  auto* cmd =
      app.add_subcommand("render", "Render optimized sprite sequences into video or PNG frames");
  cmd->add_option("sequences", args->sequences, "Sequences file from `animate` (JSON)")->required();
  cmd->add_option("--out", args->out,
                  "OUT.mkv or OUT.mp4 (video) or a folder (PNG frames with alpha)")
      ->required();
  cmd->add_option("--spec", args->spec, "Take the camera and background from this spec instead");
  cmd->add_option(
         "--codec", args->codec,
         "Video codec: h264 (default; libx264, in .mp4 mpeg4 without it), ffv1, mjpeg (.mkv only)")
      ->check(CLI::IsMember({"h264", "ffv1", "mjpeg"}));
  cmd->add_flag("--stages", args->stages, "Play the run's intermediate stages before the result");
  cmd->add_flag("--no-shadows", args->no_shadows, "Leave the contact shadows out");
  cmd->add_flag("--json", args->json, "Print what was written as JSON");
  cmd->callback([args] { Run(*args); });
}

}  // namespace ss::apps
