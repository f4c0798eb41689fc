// spritestation import VIDEO... --out SESSION (--model FILE... | --camera-height M --tilt DEG
// --hfov DEG)
//                      [--range A-B] [--empty-range A-B | --empty-clip FILE...] [--empty-frames N]
//                      [--floor FILE] [--force] [--json]:
// makes a recorded session from any video FFmpeg reads, with the empty scene the
// clean-plate keyer learns from in front (docs/import.md).
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "apps/commands.h"
#include "core/camera_model.h"
#include "core/error.h"
#include "core/log.h"
#include "core/option_checks.h"
#include "import/import_session.h"
#include "pipeline/filter/usability.h"
#include "pipeline/run/ingest.h"

namespace ss::apps {
namespace {

struct ImportArgs {
  ImportOptions options;
  std::string range, empty_range;
  double camera_height_m = 0, tilt_deg = 0, hfov_deg = 0;
  int rough_given = 0;  // how many of --camera-height, --tilt, --hfov were given
  bool json = false;
};

void RunImport(ImportArgs a) {
  ImportOptions& o = a.options;
  if (!a.range.empty()) o.range = ParseTimeRange(a.range, "--range");
  if (!a.empty_range.empty() && !o.empty_clips.empty()) {
    throw InputError("--empty-range and --empty-clip: give one source of the empty scene");
  }
  if (!a.empty_range.empty()) {
    o.empty_source = EmptySceneSource::kTimeRange;
    o.empty_range = ParseTimeRange(a.empty_range, "--empty-range");
  } else if (!o.empty_clips.empty()) {
    o.empty_source = EmptySceneSource::kClip;
  }
  if (a.rough_given > 0) {
    if (a.rough_given < 3)
      throw InputError("--camera-height, --tilt, --hfov: a rough camera needs all three");
    o.use_rough = true;
    o.rough = {a.camera_height_m, a.tilt_deg, a.hfov_deg};
  }
  if (!a.json) o.progress = [](const std::string& line) { Log("import")->info("{}", line); };
  const ImportSummary s = ImportVideos(o);
  // How each camera sees its floor (issue 38): from above, ingest stores floor sprites; an
  // upright camera that sees all of it too steeply keeps nothing.
  struct View {
    double shallowest_deg = std::nan(""), median_deg = std::nan("");
    bool from_above = false;
    std::string steep;
  };
  std::vector<View> views(s.cameras.size());
  if (!o.no_model) {
    try {
      const GroundPolygon floor = FloorForSession(s.session_dir, {});
      for (size_t i = 0; i < s.cameras.size(); ++i) {
        const CameraModel model = CameraModel::Read(
            (std::filesystem::path(s.session_dir) / (s.cameras[i].name + ".cameramodel")).string());
        const FloorMask mask(model, floor, UsabilityOptions{});
        views[i] = {mask.shallowest_view_deg(), mask.median_view_deg(), mask.FilmsFromAbove(),
                    mask.SteepViewText()};
      }
    } catch (const InputError&) {
      // no floor (nothing seen): ingest names it
    }
  }
  const auto number = [](double v) {
    return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json();
  };

  if (a.json) {
    nlohmann::json j = {{"session", s.session_dir},      {"name", s.name},
                        {"empty_scene", s.empty_source}, {"floor", s.floor_source},
                        {"seconds", s.seconds},          {"cameras", nlohmann::json::array()}};
    for (const ImportedCamera& c : s.cameras) {
      j["cameras"].push_back({{"name", c.name},
                              {"video", c.video},
                              {"frames", c.frames},
                              {"empty_frames", c.empty_frames},
                              {"corrupt_frames", c.corrupt_frames},
                              {"width", c.width},
                              {"height", c.height},
                              {"fps", c.fps},
                              {"first_timestamp_ns", c.first_timestamp_ns},
                              {"last_timestamp_ns", c.last_timestamp_ns},
                              {"model", c.model_source}});
    }
    for (size_t i = 0; i < s.cameras.size(); ++i) {
      j["cameras"][i]["shallowest_view_deg"] = number(views[i].shallowest_deg);
      j["cameras"][i]["median_view_deg"] = number(views[i].median_deg);
      j["cameras"][i]["sprites"] = views[i].from_above ? "floor" : "upright";
    }
    std::printf("%s\n", j.dump(2).c_str());
  } else {
    std::printf("session %s (\"%s\") in %.1f s; empty scene: %s; floor: %s\n",
                s.session_dir.c_str(), s.name.c_str(), s.seconds, s.empty_source.c_str(),
                s.floor_source.c_str());
    for (const ImportedCamera& c : s.cameras) {
      std::printf(
          "  %s: %s, %dx%d %s at %.3g fps: %lld frames (%.3f-%.3f s) after %lld empty-scene "
          "frames; "
          "model: %s\n",
          c.name.c_str(), c.video.c_str(), c.width, c.height, c.codec.c_str(), c.fps,
          static_cast<long long>(c.frames), c.first_timestamp_ns / 1e9, c.last_timestamp_ns / 1e9,
          static_cast<long long>(c.empty_frames), c.model_source.c_str());
      const View& view = views[static_cast<size_t>(&c - s.cameras.data())];
      if (!view.steep.empty()) {
        std::printf(
            "  %s: %s: ingest will refuse every sprite as view_too_steep (an upright billboard "
            "seen from above is a sliver)\n",
            c.name.c_str(), view.steep.c_str());
      } else if (view.from_above) {
        std::printf(
            "  %s: films its floor from above (a median view of %d degrees, steeper than "
            "pipeline.floor_view_angle_deg %s): ingest will store floor sprites\n",
            c.name.c_str(), static_cast<int>(std::floor(view.median_deg)),
            OptionProblems::Num(UsabilityOptions{}.floor_view_angle_deg).c_str());
      }
      if (c.corrupt_frames > 0) {
        std::printf("  %s: %lld damaged frames skipped (the last: %s)\n", c.name.c_str(),
                    static_cast<long long>(c.corrupt_frames), c.last_problem.c_str());
      }
    }
    if (o.empty_frames > 0 && !o.no_model) {
      std::printf("next: spritestation ingest %s --bank BANK --config %s/ingest.yaml\n",
                  s.session_dir.c_str(), s.session_dir.c_str());
    }
  }
  std::fflush(stdout);
}

}  // namespace

void AddImportCommand(CLI::App& app) {
  auto* cmd = app.add_subcommand("import", "Make a recorded session from any video FFmpeg reads");
  auto a = std::make_shared<ImportArgs>();
  ImportOptions& o = a->options;
  cmd->add_option("VIDEO", o.videos,
                  "Videos, one camera each (MP4, MKV, AVI, ...; an image sequence as a pattern: "
                  "img%04d.png, 'left*.jpg')")
      ->required();
  cmd->add_option("--out", o.out_dir, "The session folder to make")->required();
  cmd->add_flag("--force", o.force, "Replace the recorded session already at --out");
  cmd->add_option("--name", o.name, "Session name (default: the first video's file name)");
  cmd->add_option("--range", a->range,
                  "Import only START-END seconds of each video (\"10-40\", \"10-\", \"-40\")");
  cmd->add_option("--model", o.model_paths, "The camera's mrcal .cameramodel, one per video");
  cmd->add_flag("--no-model", o.no_model,
                "No camera model: footage of a calibration board, for `spritestation calibrate` "
                "(docs/import.md)");
  auto* height = cmd->add_option("--camera-height", a->camera_height_m,
                                 "Rough camera: its height above the floor, metres");
  auto* tilt = cmd->add_option("--tilt", a->tilt_deg,
                               "Rough camera: degrees its view points below the horizontal");
  auto* hfov =
      cmd->add_option("--hfov", a->hfov_deg, "Rough camera: horizontal field of view, degrees");
  cmd->add_option("--empty-range", a->empty_range,
                  "The empty scene: START-END seconds of each video (default: a per-pixel median)");
  cmd->add_option("--empty-clip", o.empty_clips, "The empty scene: a separate clip per video");
  cmd->add_option(
         "--empty-frames", o.empty_frames,
         "Empty-scene frames written in front (= ingest's keying.training_frames; 0: none)")
      ->capture_default_str();
  cmd->add_option("--median-samples", o.median_samples, "Median plate: at least this many frames")
      ->capture_default_str();
  cmd->add_option("--floor", o.floor_path,
                  "The floor polygon, JSON {\"floor\": [[x, y], ...]} in metres");
  cmd->add_option(
      "--floor-max-range", o.floor_max_range_m,
      "Without --floor: the floor seen out to this many metres (default 5 x camera height)");
  cmd->add_option("--codec", o.codec, "The session's video codec: ffv1, ffvhuff, mjpeg, h264")
      ->capture_default_str();
  cmd->add_option("--fps", o.image_sequence_fps, "Frame rate of an image sequence")
      ->capture_default_str();
  cmd->add_flag("--json", a->json, "Print the summary as JSON");
  cmd->callback([a, height, tilt, hfov] {
    a->rough_given = (height->count() > 0) + (tilt->count() > 0) + (hfov->count() > 0);
    RunImport(*a);
  });
}

}  // namespace ss::apps
