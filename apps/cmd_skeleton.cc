// spritestation skeleton track|import: 2D skeletons for a clip (seed 003 §2.1,
// docs/skeletons.md). `track` carries the user's first-frame joints through a clip with
// pyramidal Lucas-Kanade and interpolates the frames marked occluded; `import` reads
// DeepLabCut CSV, OpenPose JSON or COCO keypoints through a joint mapping.
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>

#include "animate/skeleton/importers.h"
#include "animate/skeleton/joint_mapping.h"
#include "animate/skeleton/lk_tracker.h"
#include "animate/skeleton/skeleton_json.h"
#include "apps/commands.h"
#include "capture/recording/video_reader.h"
#include "core/error.h"
#include "core/frame.h"
#include "core/log.h"
#include "core/session.h"

namespace ss::apps {
namespace {

namespace fs = std::filesystem;

// "3,10-14,40-41" -> frame indices (0-based, inclusive ranges).
std::vector<int> ParseFrameList(const std::string& text) {
  std::vector<int> frames;
  size_t at = 0;
  while (at < text.size()) {
    size_t end = text.find(',', at);
    if (end == std::string::npos) end = text.size();
    const std::string item = text.substr(at, end - at);
    at = end + 1;
    if (item.empty()) continue;
    try {
      const size_t dash = item.find('-');
      size_t used = 0;
      const int first = std::stoi(item.substr(0, dash), &used);
      if (used != (dash == std::string::npos ? item.size() : dash))
        throw std::invalid_argument(item);
      int last = first;
      if (dash != std::string::npos) {
        last = std::stoi(item.substr(dash + 1), &used);
        if (used != item.size() - dash - 1) throw std::invalid_argument(item);
      }
      if (first < 0 || last < first) throw std::invalid_argument(item);
      for (int f = first; f <= last; ++f) frames.push_back(f);
    } catch (const std::exception&) {
      throw InputError("--occluded",
                       "expected frame numbers and ranges like 3,10-14, got '" + item + "'");
    }
  }
  return frames;
}

// The frames of a clip, one at a time: a folder of images (sorted by name), a recorded
// session (one camera) or one camera's video inside a session.
class ClipFrames {
 public:
  ClipFrames(const std::string& path, const std::string& camera) {
    std::error_code ec;
    fs::path session_dir;
    std::string video_name;
    if (fs::is_directory(path, ec) && fs::exists(fs::path(path) / "session.json")) {
      session_dir = path;
    } else if (fs::is_regular_file(path, ec) &&
               fs::exists(fs::path(path).parent_path() / "session.json")) {
      session_dir = fs::path(path).parent_path();
      video_name = fs::path(path).filename().string();
    } else if (fs::is_directory(path, ec)) {
      for (const auto& entry : fs::directory_iterator(path)) {
        std::string ext = entry.path().extension().string();
        std::transform(ext.begin(), ext.end(), ext.begin(), ::tolower);
        if (ext == ".png" || ext == ".jpg" || ext == ".jpeg" || ext == ".bmp" || ext == ".tif" ||
            ext == ".tiff") {
          images_.push_back(entry.path().string());
        }
      }
      std::sort(images_.begin(), images_.end());
      if (images_.empty())
        throw InputError(path, "no session.json and no images (png, jpg, bmp, tif) in this folder");
      clip_ = fs::path(path).filename().string();
      return;
    } else {
      throw InputError(
          path,
          "expected a recorded session folder, a camera video inside one, or a folder of images "
          "(a video outside a session has no pixel format and size to decode it with)");
    }
    const SessionInfo info = ReadSessionInfo(session_dir.string());
    const SessionCamera* chosen = nullptr;
    for (const auto& c : info.cameras) {
      if ((!video_name.empty() && c.video == video_name) ||
          (video_name.empty() && (camera.empty() || c.name == camera))) {
        chosen = &c;
        break;
      }
    }
    if (!chosen) {
      throw InputError(path, video_name.empty()
                                 ? "the session has no camera '" + camera + "'"
                                 : "session.json lists no camera with video '" + video_name + "'");
    }
    camera_ = *chosen;
    fps_ = chosen->fps;
    clip_ = info.name + "/" + chosen->name;
    reader_ = std::make_unique<VideoReader>((session_dir / chosen->video).string(),
                                            chosen->pixel_format, chosen->width, chosen->height);
  }

  // The next image; false at the end. `damaged` is set when the frame could not be read
  // (the previous image is returned in its place).
  bool Next(cv::Mat* image, bool* damaged) {
    *damaged = false;
    if (!reader_) {
      if (next_ >= images_.size()) return false;
      *image = cv::imread(images_[next_], cv::IMREAD_COLOR);
      if (image->empty()) throw InputError(images_[next_], "cannot read the image");
      ++next_;
      return true;
    }
    const VideoReader::Result r = reader_->Next(pixels_);
    if (r.status == VideoReader::Status::kEnd) return false;
    if (r.status == VideoReader::Status::kCorrupt) {
      Log("animate.skeleton")->warn("{}: {}", reader_->path(), r.problem);
      if (last_.empty())
        throw WorkError(reader_->path(), "the first frame cannot be read: " + r.problem);
      *image = last_;
      *damaged = true;
      return true;
    }
    last_ = ToBgr(Frame::Owned(camera_.pixel_format, camera_.width, camera_.height, pixels_));
    *image = last_;
    return true;
  }

  const std::string& clip() const { return clip_; }
  double fps() const { return fps_; }

 private:
  std::vector<std::string> images_;
  size_t next_ = 0;
  SessionCamera camera_;
  std::unique_ptr<VideoReader> reader_;
  std::vector<uint8_t> pixels_;
  cv::Mat last_;
  std::string clip_;
  double fps_ = 0;
};

// The user's joints: a skeleton sequence file (each of its frames gives the joints at
// that frame number; the first must be frame 0), or {"skeleton": ..., "joints": {...}}
// for frame 0 alone.
std::map<int64_t, SkeletonFrame> ReadInitialJoints(const std::string& path,
                                                   const std::string& skeleton_path,
                                                   SkeletonDef* def) {
  std::ifstream in(path);
  if (!in) throw InputError(path, "cannot open the initial joints");
  nlohmann::json json;
  try {
    json = nlohmann::json::parse(in);
  } catch (const nlohmann::json::exception& e) {
    throw InputError(path, std::string("not valid JSON: ") + e.what());
  }
  std::map<int64_t, SkeletonFrame> given;
  try {
    if (json.is_object() && json.contains("format")) {
      const SkeletonSequence s = SkeletonSequenceFromJson(json, path);
      *def = s.skeleton;
      for (const auto& f : s.frames) given[f.frame] = f;
    } else {
      if (!json.is_object() || !json.contains("joints")) {
        throw InputError(
            path, "expected a skeleton sequence or {\"skeleton\", \"joints\": {name: [x, y]}}");
      }
      if (json.contains("skeleton")) {
        *def = SkeletonDefFromJson(json["skeleton"], path);
      } else if (!skeleton_path.empty()) {
        *def = LoadSkeletonDef(skeleton_path);
      } else {
        *def = HumanSkeleton();
      }
      SkeletonFrame f = SkeletonFrameFromJson(json["joints"], *def, path + ": joints");
      f.frame = 0;
      given[0] = f;
    }
  } catch (const nlohmann::json::exception& e) {
    throw InputError(path, e.what());
  }
  if (given.empty() || given.begin()->first != 0)
    throw InputError(path, "the joints of frame 0 are required");
  const auto& first = given.begin()->second.joints;
  if (std::none_of(first.begin(), first.end(), [](const JointSample& j) { return j.present; })) {
    throw InputError(path, "frame 0 places no joint");
  }
  return given;
}

struct TrackArgs {
  std::string clip, init, out, occluded, camera, skeleton;
  LkOptions lk;
  bool json = false;
};

void Track(const TrackArgs& a) {
  SkeletonDef def;
  const auto given = ReadInitialJoints(a.init, a.skeleton, &def);
  std::vector<int> occluded_list =
      a.occluded.empty() ? std::vector<int>{} : ParseFrameList(a.occluded);
  std::sort(occluded_list.begin(), occluded_list.end());
  ClipFrames clip(a.clip, a.camera);
  LkJointTracker tracker(def, a.lk);
  const std::vector<bool> all(def.joints.size(), true);
  cv::Mat image;
  bool damaged = false;
  int frame = 0, damaged_frames = 0;
  while (clip.Next(&image, &damaged)) {
    const bool marked = std::binary_search(occluded_list.begin(), occluded_list.end(), frame);
    damaged_frames += damaged ? 1 : 0;
    const auto it = given.find(frame);
    tracker.AddFrame(image, (marked || damaged) && frame > 0 ? all : std::vector<bool>{},
                     it == given.end() ? nullptr : &it->second);
    ++frame;
  }
  if (frame == 0) throw InputError(a.clip, "the clip has no frames");
  if (!occluded_list.empty() && occluded_list.back() >= frame) {
    throw InputError("--occluded", "frame " + std::to_string(occluded_list.back()) +
                                       " is past the clip's " + std::to_string(frame) + " frames");
  }
  TrackingResult r = tracker.Finish();
  r.sequence.clip = clip.clip();
  r.sequence.fps = clip.fps();
  WriteSkeletonSequence(r.sequence, a.out);
  int interpolated = 0, missing = 0;
  for (const auto& f : r.sequence.frames) {
    for (const auto& j : f.joints) {
      interpolated += j.interpolated ? 1 : 0;
      missing += j.present ? 0 : 1;
    }
  }
  if (a.json) {
    nlohmann::json failures = nlohmann::json::array();
    for (const auto& f : r.failures) {
      nlohmann::json item = {
          {"frame", f.frame}, {"joint", def.joints[f.joint]}, {"reason", f.reason}};
      if (f.forward_backward_px >= 0) item["forward_backward_px"] = f.forward_backward_px;
      failures.push_back(item);
    }
    const nlohmann::json j = {{"out", a.out},
                              {"clip", r.sequence.clip},
                              {"frames", frame},
                              {"joints", def.joints.size()},
                              {"interpolated_joints", interpolated},
                              {"missing_joints", missing},
                              {"damaged_frames", damaged_frames},
                              {"failures", failures}};
    std::printf("%s\n", j.dump(2).c_str());
    return;
  }
  std::printf("tracked %zu joints through %d frames of %s -> %s\n", def.joints.size(), frame,
              r.sequence.clip.c_str(), a.out.c_str());
  std::printf(
      "interpolated %d joint positions, %d missing, %d damaged frames, %zu tracking failures\n",
      interpolated, missing, damaged_frames, r.failures.size());
  std::map<int, std::vector<std::string>> by_frame;
  for (const auto& f : r.failures)
    by_frame[f.frame].push_back(def.joints[f.joint] + " (" + f.reason + ")");
  for (const auto& [f, list] : by_frame) {
    std::string line;
    for (const auto& s : list) line += (line.empty() ? "" : ", ") + s;
    std::printf("  frame %d: %s\n", f, line.c_str());
  }
}

struct SkeletonImportArgs {
  std::string format, file, mapping, out, individual, camera;
  float min_confidence = -1;
  int person = 0;
  bool json = false;
};

void Import(const SkeletonImportArgs& a) {
  JointMapping mapping;
  if (!a.mapping.empty()) {
    mapping = LoadJointMapping(a.mapping);
  } else if (a.format == "openpose") {
    mapping = Body25ToHuman14();
  } else if (a.format == "coco") {
    mapping = Coco17ToHuman14();
  } else if (a.format == "synth") {
    mapping = IdentityMapping(HumanSkeleton());  // the figures' joints are human14's
  } else {
    throw InputError("--mapping",
                     "DeepLabCut body parts are named by the project: give a joint mapping file "
                     "(docs/skeletons.md)");
  }
  SkeletonImportOptions options;
  if (a.min_confidence >= 0) options.min_confidence = a.min_confidence;
  options.individual = a.individual;
  options.person = a.person;
  SkeletonSequence s;
  if (a.format == "deeplabcut") {
    s = ImportDeepLabCutCsv(a.file, mapping, options);
  } else if (a.format == "openpose") {
    s = ImportOpenPoseJson(a.file, mapping, options);
  } else if (a.format == "synth") {
    s = ImportSynthTruth(a.file, a.camera, mapping, options);
  } else {
    s = ImportCocoKeypoints(a.file, mapping, options);
  }
  WriteSkeletonSequence(s, a.out);
  int present = 0, total = 0;
  for (const auto& f : s.frames) {
    for (const auto& j : f.joints) {
      present += j.present ? 1 : 0;
      ++total;
    }
  }
  if (a.json) {
    const nlohmann::json j = {
        {"out", a.out},       {"format", a.format},        {"skeleton", s.skeleton.name},
        {"frames", s.size()}, {"joints_present", present}, {"joints_total", total}};
    std::printf("%s\n", j.dump(2).c_str());
    return;
  }
  std::printf("imported %d frames (%s, skeleton %s, %d of %d joints present) -> %s\n", s.size(),
              a.format.c_str(), s.skeleton.name.c_str(), present, total, a.out.c_str());
}

}  // namespace

void AddSkeletonCommand(CLI::App& app) {
  CLI::App* cmd =
      app.add_subcommand("skeleton", "Track or import 2D skeletons for a clip (docs/skeletons.md)");
  cmd->require_subcommand(1);

  auto track = std::make_shared<TrackArgs>();
  CLI::App* t =
      cmd->add_subcommand("track", "Carry the first frame's joints through a clip (Lucas-Kanade)");
  t->add_option("clip", track->clip,
                "A recorded session folder, a camera video in one, or a folder of images")
      ->required();
  t->add_option("--init", track->init,
                "JOINTS.json: the joints of frame 0 (and of any later frame to re-seed)")
      ->required();
  t->add_option("--out", track->out, "SKEL.json: the skeleton sequence written")->required();
  t->add_option("--occluded", track->occluded,
                "Frames the user marks occluded, e.g. 10-14,30 (interpolated)");
  t->add_option("--camera", track->camera, "The session's camera (default: the first)");
  t->add_option("--skeleton", track->skeleton,
                "Skeleton definition file when JOINTS.json names none (default human14)");
  t->add_option("--window", track->lk.window_px, "Lucas-Kanade window, pixels")
      ->capture_default_str();
  t->add_option("--levels", track->lk.pyramid_levels, "Pyramid levels")->capture_default_str();
  t->add_option("--max-fb-error", track->lk.max_forward_backward_px,
                "A joint whose forward-backward error exceeds this (pixels) is reported lost")
      ->capture_default_str();
  t->add_flag("--json", track->json, "Print the report as JSON");
  t->callback([track] { Track(*track); });

  auto import = std::make_shared<SkeletonImportArgs>();
  CLI::App* i = cmd->add_subcommand(
      "import", "Read DeepLabCut, OpenPose or COCO keypoints, or synth joint truth");
  i->add_option("--format", import->format, "deeplabcut | openpose | coco | synth")
      ->required()
      ->check(CLI::IsMember({"deeplabcut", "openpose", "coco", "synth"}));
  i->add_option("file", import->file,
                "CSV (DeepLabCut), a folder of or one *_keypoints.json (OpenPose), COCO JSON, "
                "a synthetic session (synth: its truth/<camera>/joints.csv)")
      ->required();
  i->add_option("--camera", import->camera,
                "synth: the camera whose projected joints are read (default: the first)");
  i->add_option("--mapping", import->mapping,
                "Joint mapping file (required for DeepLabCut; OpenPose BODY_25 and COCO-17 have "
                "built-in ones)");
  i->add_option("--out", import->out, "SKEL.json: the skeleton sequence written")->required();
  i->add_option("--min-confidence", import->min_confidence,
                "Keypoints below this become missing joints");
  i->add_option("--individual", import->individual, "DeepLabCut multi-animal: which individual");
  i->add_option("--person,--subject", import->person,
                "OpenPose: index into people[]; synth: the subject");
  i->add_flag("--json", import->json, "Print the report as JSON");
  i->callback([import] { Import(*import); });
}

}  // namespace ss::apps
