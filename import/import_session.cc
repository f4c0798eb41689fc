#include "import/import_session.h"

#include <signal.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <optional>

#include "capture/recording/session_writer.h"
#include "core/error.h"
#include "core/log.h"
#include "core/recording_codecs.h"
#include "import/empty_scene.h"
#include "import/source_video.h"

namespace ss {
namespace {

namespace fs = std::filesystem;

std::string Seconds(double s) {
  char text[32];
  std::snprintf(text, sizeof(text), "%g", s);
  return text;
}

std::string RangeText(const TimeRange& r) {
  return Seconds(r.start_s) + "-" + (std::isinf(r.end_s) ? std::string() : Seconds(r.end_s));
}

// Refuses a range that lies (partly) outside a video whose length is known.
void CheckRangeInVideo(const TimeRange& r, const SourceVideo& video, const std::string& flag) {
  const double length = video.duration_s();
  if (length <= 0) return;  // unknown: checked by finding no frame in it
  if (r.start_s >= length) {
    throw InputError(flag, "starts at " + Seconds(r.start_s) + " s but " + video.path() + " is " +
                               Seconds(length) + " s long");
  }
  // One frame of slack: containers round their duration.
  const double frame = video.fps() > 0 ? 1.0 / video.fps() : 0.1;
  if (!std::isinf(r.end_s) && r.end_s > length + frame) {
    throw InputError(flag, "ends at " + Seconds(r.end_s) + " s but " + video.path() + " is " +
                               Seconds(length) + " s long");
  }
}

// Reads the frames of `range`, keeping an even spread of at least `wanted` of them.
EvenFrameSampler SampleRange(SourceVideo& video, const TimeRange& range, int wanted) {
  EvenFrameSampler sampler(wanted);
  video.SeekBefore(range.start_s);
  SourceFrame f;
  while (video.Next(&f)) {
    const double t = f.timestamp_ns / 1e9;
    if (t < range.start_s) continue;
    if (t >= range.end_s) break;
    sampler.Offer(f.bgr);
  }
  return sampler;
}

GroundPolygon ReadFloorFile(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw InputError(path, "cannot read the floor file (--floor)");
  nlohmann::json j;
  try {
    in >> j;
  } catch (const nlohmann::json::exception& e) {
    throw InputError(path, std::string("not valid JSON: ") + e.what());
  }
  if (!j.is_object() || !j.contains("floor") || !j["floor"].is_array()) {
    throw InputError(path, "expected {\"floor\": [[x, y], ...]} (ground metres)");
  }
  std::vector<Eigen::Vector2d> vertices;
  for (const auto& p : j["floor"]) {
    if (!p.is_array() || p.size() != 2 || !p[0].is_number() || !p[1].is_number()) {
      throw InputError(path, "floor: every point must be [x, y] in metres");
    }
    vertices.emplace_back(p[0].get<double>(), p[1].get<double>());
  }
  if (vertices.size() > GroundPolygon::kMaxVertices)
    throw InputError(path, "floor: " + std::to_string(vertices.size()) +
                               " points; a floor polygon has at most " +
                               std::to_string(GroundPolygon::kMaxVertices));
  GroundPolygon polygon(std::move(vertices));
  if (!polygon.IsSimple())
    throw InputError(path, "floor: not a simple polygon of at least 3 points");
  return polygon;
}

void WriteText(const fs::path& path, const std::string& text) {
  std::ofstream out(path);
  out << text;
  if (!out.flush()) throw WorkError(path.string(), "cannot write it");
}

// Makes the camera's model: its file, or the rough camera; none with no_model.
std::optional<CameraModel> ModelFor(const ImportOptions& o, size_t i, const SourceVideo& video,
                                    std::string* source) {
  if (o.no_model) {
    *source = "none";
    return std::nullopt;
  }
  if (o.use_rough) {
    *source = "rough: height " + Seconds(o.rough.height_m) + " m, tilt " +
              Seconds(o.rough.tilt_deg) + " deg, hfov " + Seconds(o.rough.hfov_deg) + " deg";
    return RoughCameraModel(o.rough, video.width(), video.height());
  }
  CameraModel m = CameraModel::Read(o.model_paths[i]);
  if (m.width() != video.width() || m.height() != video.height()) {
    throw InputError(o.model_paths[i], "the model is for " + std::to_string(m.width()) + "x" +
                                           std::to_string(m.height()) + " images but " +
                                           video.path() + " is " + std::to_string(video.width()) +
                                           "x" + std::to_string(video.height()));
  }
  *source = o.model_paths[i];
  return m;
}

// The empty scene of camera `i`: exactly o.empty_frames frames of the video's size.
std::vector<cv::Mat> EmptyScene(const ImportOptions& o, size_t i, const SourceVideo& main,
                                ImportedCamera* cam) {
  const int n = o.empty_frames;
  if (n == 0) return {};
  std::vector<cv::Mat> samples;
  std::vector<cv::Mat> out;
  if (o.empty_source == EmptySceneSource::kMedian) {
    SourceVideo video(o.videos[i], o.image_sequence_fps);
    samples = SampleRange(video, o.range, o.median_samples).frames();
    if (samples.size() < 3) {
      throw InputError("--range", std::to_string(samples.size()) + " frames of " + o.videos[i] +
                                      " lie in " + RangeText(o.range) +
                                      " s; a median plate needs at least 3");
    }
    const RobustBackground background = MedianAndSpread(samples);
    double share_sum = 0;
    for (const int k : EvenIndices(static_cast<int>(samples.size()), n)) {
      double kept = 0;
      out.push_back(Winsorized(samples[k], background, o.winsor_spreads, &kept));
      share_sum += kept;
    }
    cam->median_background_share = share_sum / n;
    return out;
  }
  const bool clip = o.empty_source == EmptySceneSource::kClip;
  const std::string path = clip ? o.empty_clips[i] : o.videos[i];
  const std::string flag = clip ? "--empty-clip" : "--empty-range";
  SourceVideo video(path, o.image_sequence_fps);
  if (video.width() != main.width() || video.height() != main.height()) {
    throw InputError(path, "the empty scene is " + std::to_string(video.width()) + "x" +
                               std::to_string(video.height()) + " but " + main.path() + " is " +
                               std::to_string(main.width()) + "x" + std::to_string(main.height()));
  }
  const TimeRange range = clip ? TimeRange{} : o.empty_range;
  if (!clip) CheckRangeInVideo(range, video, flag);
  samples = SampleRange(video, range, n).frames();
  if (static_cast<int>(samples.size()) < n) {
    throw InputError(flag, path + " holds " + std::to_string(samples.size()) + " frames" +
                               (clip ? "" : " in " + RangeText(range) + " s") +
                               "; the keyer learns from " + std::to_string(n) +
                               " (--empty-frames)");
  }
  for (const int k : EvenIndices(static_cast<int>(samples.size()), n)) out.push_back(samples[k]);
  return out;
}

Frame BgrFrame(const cv::Mat& bgr, uint64_t sequence, int64_t timestamp_ns) {
  Frame f =
      Frame::Borrowed(PixelFormat::kBGR8, bgr.cols, bgr.rows, bgr.data, bgr.total() * 3, [] {});
  f.sequence = sequence;
  f.timestamp_ns = timestamp_ns;
  return f;
}

// Writes camera `i` (its empty scene, then its range) and fills `cam`.
void ImportCamera(const ImportOptions& o, size_t i, const CameraModel* model, SessionWriter& writer,
                  ImportedCamera* cam) {
  SourceVideo video(o.videos[i], o.image_sequence_fps);
  const std::vector<cv::Mat> empty = EmptyScene(o, i, video, cam);
  cam->empty_frames = static_cast<int64_t>(empty.size());
  SourceCamera source;
  source.name = cam->name;
  source.width = video.width();
  source.height = video.height();
  source.format = PixelFormat::kBGR8;
  source.fps = video.fps();
  const int index = writer.AddCamera(source, model);

  video.SeekBefore(o.range.start_s);
  SourceFrame f;
  uint64_t sequence = 0;
  bool first = true;
  while (video.Next(&f)) {
    const double t = f.timestamp_ns / 1e9;
    if (t < o.range.start_s) continue;
    if (t >= o.range.end_s) break;
    if (first) {
      // The empty scene just before the first frame, a nominal frame apart (its times are made up;
      // import.json says so, and ingest only learns from these frames).
      const int64_t step =
          static_cast<int64_t>(std::llround(1e9 / (video.fps() > 0 ? video.fps() : 25.0)));
      for (size_t k = 0; k < empty.size(); ++k) {
        Frame e = BgrFrame(empty[k], sequence++,
                           f.timestamp_ns - static_cast<int64_t>(empty.size() - k) * step);
        e.camera = index;
        writer.Write(e);
      }
      cam->first_timestamp_ns = f.timestamp_ns;
      first = false;
    }
    Frame frame = BgrFrame(f.bgr, sequence++, f.timestamp_ns);
    frame.camera = index;
    writer.Write(frame);
    cam->last_timestamp_ns = f.timestamp_ns;
    ++cam->frames;
    if (o.progress && cam->frames % 250 == 0) {
      o.progress(cam->name + ": " + std::to_string(cam->frames) + " frames, at " + Seconds(t) +
                 " s");
    }
  }
  cam->corrupt_frames = video.corrupt_frames();
  cam->last_problem = video.last_problem();
  if (cam->frames == 0) {
    throw InputError(
        "--range",
        "no frame of " + o.videos[i] + " lies in " + RangeText(o.range) + " s" +
            (video.corrupt_frames() > 0 ? " that decodes (" + video.last_problem() + ")" : ""));
  }
  if (cam->corrupt_frames > 0) {
    Log("import")->warn("{}: {} damaged frames skipped, the last: {}", o.videos[i],
                        cam->corrupt_frames, cam->last_problem);
  }
}

std::string IngestYaml(int empty_frames) {
  return "# Written by `spritestation import`: how this session is ingested.\n"
         "#   spritestation ingest SESSION --bank BANK --config SESSION/ingest.yaml\n"
         "# Each camera's first " +
         std::to_string(empty_frames) +
         " frames are the empty scene (import.json says where they came from);\n"
         "# the keyer learns the background from them.\n"
         "keying:\n"
         "  method: clean_plate\n"
         "  training_frames: " +
         std::to_string(empty_frames) +
         "\n"
         "# People walk at ~1.4 m/s: past the tracker's default limit (1 m/s, for small animals) "
         "a\n"
         "# walker's clip breaks every few frames (vtest.avi, first 30 s: 110 sprites kept at 1 "
         "m/s,\n"
         "# 495 at 2.5 m/s).\n"
         "pipeline:\n"
         "  max_speed_m_per_s: 2.5\n";
}

nlohmann::json SummaryJson(const ImportOptions& o, const ImportSummary& s) {
  nlohmann::json j;
  j["format_version"] = 1;
  j["empty_scene"] = s.empty_source;
  j["empty_frames"] = o.empty_frames;
  j["range"] = RangeText(o.range);
  j["floor"] = s.floor_source;
  j["cameras"] = nlohmann::json::array();
  for (const ImportedCamera& c : s.cameras) {
    nlohmann::json cj = {{"name", c.name},
                         {"video", c.video},
                         {"video_codec", c.codec},
                         {"width", c.width},
                         {"height", c.height},
                         {"rotation_deg", c.rotation_deg},
                         {"fps", c.fps},
                         {"frames", c.frames},
                         {"empty_frames", c.empty_frames},
                         {"corrupt_frames", c.corrupt_frames},
                         {"first_timestamp_ns", c.first_timestamp_ns},
                         {"last_timestamp_ns", c.last_timestamp_ns},
                         {"model", c.model_source}};
    if (o.empty_source == EmptySceneSource::kMedian)
      cj["median_background_share"] = c.median_background_share;
    j["cameras"].push_back(cj);
  }
  return j;
}

// Removes what a killed import of the same --out left beside it: `.STEM.import-PID` folders
// whose process is gone (a running import's is left alone).
void RemoveAbandonedImports(const fs::path& parent, const std::string& stem) {
  const std::string prefix = "." + stem + ".import-";
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(parent, ec)) {
    const std::string name = entry.path().filename().string();
    if (name.rfind(prefix, 0) != 0 || !entry.is_directory(ec)) continue;
    const std::string digits = name.substr(prefix.size());
    if (digits.empty() || digits.find_first_not_of("0123456789") != std::string::npos) continue;
    const long pid = std::strtol(digits.c_str(), nullptr, 10);
    // Alive, or not ours to judge: left alone.
    if (pid <= 0 || kill(static_cast<pid_t>(pid), 0) == 0 || errno != ESRCH) continue;
    Log("import")->info("{}: removing what an interrupted import left", entry.path().string());
    fs::remove_all(entry.path(), ec);
  }
}

// The video's file stem, without an image sequence's pattern characters ("left[01]*.jpg" ->
// "left01").
std::string NameFromPath(const std::string& path) {
  std::string name;
  for (const char c : fs::path(path).stem().string()) {
    if (std::string("%*?[]").find(c) == std::string::npos) name += c;
  }
  return name.empty() ? "import" : name;
}

std::string EmptySourceText(const ImportOptions& o) {
  if (o.empty_frames == 0) return "none";
  switch (o.empty_source) {
    case EmptySceneSource::kMedian:
      return "median";
    case EmptySceneSource::kTimeRange:
      return "range " + RangeText(o.empty_range);
    case EmptySceneSource::kClip:
      return "clip";
  }
  return "";
}

// Refuses to replace anything but a recorded session (or an empty folder).
void CheckOut(const ImportOptions& o) {
  std::error_code ec;
  if (!fs::exists(o.out_dir, ec)) return;
  if (!fs::is_directory(o.out_dir, ec))
    throw InputError(o.out_dir, "exists and is not a folder (--out)");
  if (fs::is_empty(o.out_dir, ec)) return;
  if (!o.force)
    throw InputError(o.out_dir,
                     "already exists (--out); give --force to replace the session in it");
  if (!fs::exists(fs::path(o.out_dir) / "session.json", ec)) {
    throw InputError(
        o.out_dir,
        "exists and holds no session.json: not a recorded session, so --force does not "
        "replace it");
  }
}

}  // namespace

TimeRange ParseTimeRange(const std::string& text, const std::string& flag) {
  const auto bad = [&] {
    return InputError(
        flag,
        "expected START-END in seconds (\"12.5-30\", \"12.5-\" to the end, \"-30\" from the "
        "start), got \"" +
            text + "\"");
  };
  const size_t dash = text.find('-');
  if (dash == std::string::npos || text.find('-', dash + 1) != std::string::npos) throw bad();
  const auto number = [&](const std::string& s, double fallback) {
    if (s.empty()) return fallback;
    char* end = nullptr;
    const double v = std::strtod(s.c_str(), &end);
    if (end != s.c_str() + s.size() || !std::isfinite(v) || v < 0) throw bad();
    return v;
  };
  TimeRange r;
  r.start_s = number(text.substr(0, dash), 0);
  r.end_s = number(text.substr(dash + 1), std::numeric_limits<double>::infinity());
  if (!(r.end_s > r.start_s))
    throw InputError(
        flag, "ends (" + Seconds(r.end_s) + " s) before it starts (" + Seconds(r.start_s) + " s)");
  return r;
}

bool ImportOptions::IsValid(std::string* why) const {
  if (videos.empty()) return *why = "VIDEO: give at least one video", false;
  if (out_dir.empty()) return *why = "--out: give the session folder to make", false;
  if (FindRecordingCodec(codec) == nullptr) {
    return *why = "--codec: expected " + RecordingCodecNames() + ", got \"" + codec + "\"", false;
  }
  if (int{use_rough} + int{!model_paths.empty()} + int{no_model} != 1) {
    return *why =
               "give the camera model: --model FILE (one per video), or --camera-height, --tilt "
               "and --hfov, or "
               "--no-model (footage for `spritestation calibrate`)",
           false;
  }
  if (!model_paths.empty() && model_paths.size() != videos.size()) {
    return *why = "--model: " + std::to_string(model_paths.size()) + " models for " +
                  std::to_string(videos.size()) + " videos; give one per video, in the same order",
           false;
  }
  if (use_rough && videos.size() > 1) {
    return *why =
               "--camera-height/--tilt/--hfov describe one camera; with several videos give "
               "--model per video",
           false;
  }
  if (use_rough && !rough.IsValid(why)) return false;
  if (videos.size() > 1 && floor_path.empty()) {
    return *why = "--floor: with several cameras give the floor they share", false;
  }
  if (empty_source == EmptySceneSource::kClip && empty_clips.size() != videos.size()) {
    return *why = "--empty-clip: " + std::to_string(empty_clips.size()) + " clips for " +
                  std::to_string(videos.size()) + " videos; give one per video",
           false;
  }
  if (!(empty_frames >= 0 && empty_frames <= 1000)) {
    return *why = "--empty-frames: expected 0 to 1000, got " + std::to_string(empty_frames), false;
  }
  if (!(median_samples >= 3 && median_samples <= 255)) {
    return *why = "--median-samples: expected 3 to 255, got " + std::to_string(median_samples),
           false;
  }
  if (!(image_sequence_fps > 0 && image_sequence_fps <= 1000)) {
    return *why = "--fps: expected a frame rate > 0, got " + std::to_string(image_sequence_fps),
           false;
  }
  if (!(floor_max_range_m >= 0)) return *why = "--floor-max-range: expected metres >= 0", false;
  return true;
}

ImportSummary ImportVideos(const ImportOptions& o) {
  const auto start = std::chrono::steady_clock::now();
  std::string why;
  if (!o.IsValid(&why)) throw InputError(why);
  CheckOut(o);

  // Everything that can be refused is checked before anything is written.
  ImportSummary summary;
  std::vector<std::optional<CameraModel>> models;
  for (size_t i = 0; i < o.videos.size(); ++i) {
    SourceVideo video(o.videos[i], o.image_sequence_fps);
    CheckRangeInVideo(o.range, video, "--range");
    if (o.empty_source == EmptySceneSource::kTimeRange)
      CheckRangeInVideo(o.empty_range, video, "--empty-range");
    ImportedCamera cam;
    cam.name = o.videos.size() == 1 ? "cam0" : "cam" + std::to_string(i);
    cam.video = o.videos[i];
    cam.codec = video.codec();
    cam.width = video.width();
    cam.height = video.height();
    cam.fps = video.fps();
    cam.rotation_deg = video.rotation_deg();
    models.push_back(ModelFor(o, i, video, &cam.model_source));
    summary.cameras.push_back(cam);
  }
  GroundPolygon floor;
  if (!o.floor_path.empty()) {
    floor = ReadFloorFile(o.floor_path);
    summary.floor_source = o.floor_path;
  } else if (models[0]) {
    const double range_m =
        o.floor_max_range_m > 0 ? o.floor_max_range_m : 5 * models[0]->CentreInGround().z();
    floor = VisibleFloor(*models[0], range_m);
    summary.floor_source =
        "what " + summary.cameras[0].name + " sees within " + Seconds(range_m) + " m";
  } else {
    summary.floor_source = "none (no camera model)";
  }
  summary.empty_source = EmptySourceText(o);

  const fs::path out = fs::absolute(o.out_dir).lexically_normal();
  const std::string stem = out.filename().string();
  summary.name = o.name.empty() ? NameFromPath(o.videos[0]) : o.name;
  summary.session_dir = o.out_dir;
  std::error_code ec;
  fs::create_directories(out.parent_path(), ec);
  RemoveAbandonedImports(out.parent_path(), stem);
  const fs::path temp = out.parent_path() / ("." + stem + ".import-" + std::to_string(getpid()));
  fs::remove_all(temp, ec);
  try {
    RecordingOptions recording;
    recording.codec = o.codec;
    recording.flush_interval_ms = 1000;
    {
      SessionWriter writer(temp.string(), summary.name, recording);
      for (size_t i = 0; i < o.videos.size(); ++i) {
        if (o.progress)
          o.progress(summary.cameras[i].name + ": " + o.videos[i] + " (" + summary.empty_source +
                     ")");
        ImportCamera(o, i, models[i] ? &*models[i] : nullptr, writer, &summary.cameras[i]);
      }
      writer.Close();
    }
    if (!floor.empty()) {
      nlohmann::json enclosure;
      enclosure["floor"] = nlohmann::json::array();
      for (const Eigen::Vector2d& v : floor.vertices())
        enclosure["floor"].push_back({v.x(), v.y()});
      enclosure["source"] = summary.floor_source;
      WriteText(temp / "enclosure.json", enclosure.dump(2) + "\n");
    }
    if (o.empty_frames > 0) WriteText(temp / "ingest.yaml", IngestYaml(o.empty_frames));
    WriteText(temp / "import.json", SummaryJson(o, summary).dump(2) + "\n");

    // Into place: an existing session (checked above, --force) only now makes way.
    if (fs::exists(out)) {
      const fs::path old =
          out.parent_path() / ("." + stem + ".replaced-" + std::to_string(getpid()));
      fs::rename(out, old);
      fs::rename(temp, out);
      fs::remove_all(old);
    } else {
      fs::rename(temp, out);
    }
  } catch (const fs::filesystem_error& e) {
    fs::remove_all(temp, ec);
    throw WorkError(o.out_dir, std::string("cannot write the session: ") + e.what());
  } catch (...) {
    fs::remove_all(temp, ec);
    throw;
  }
  summary.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return summary;
}

}  // namespace ss
