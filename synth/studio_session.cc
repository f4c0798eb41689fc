#include "synth/studio_session.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <memory>
#include <mutex>
#include <thread>
#include <vector>

#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>

#include "capture/recording/session_writer.h"
#include "core/camera_model.h"
#include "core/contact_point.h"
#include "core/error.h"
#include "core/log.h"
#include "core/option_checks.h"
#include "core/recording_codecs.h"
#include "synth/directors.h"
#include "synth/renderer.h"
#include "synth/scene.h"

namespace ss::synth {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;
using nlohmann::json;

constexpr int kTruthVersion = 1;
constexpr int kChunkFrames = 16;  // frames simulated ahead of the camera workers

double Since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

// CPU seconds of the calling thread / of the whole process (the machine may be shared).
double ThreadCpuS() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}
double ProcessCpuS() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

std::string FrameName(int frame) {
  char name[32];
  std::snprintf(name, sizeof(name), "%06d.png", frame);
  return name;
}

// A CSV file written through a buffer; WorkError naming it when it cannot be written.
class CsvFile {
 public:
  CsvFile(const std::string& path, const std::string& header) : path_(path), out_(path) {
    if (!out_) throw WorkError(path, "cannot create the truth file");
    out_ << header << '\n';
  }
  void Row(const char* format, ...) __attribute__((format(printf, 2, 3))) {
    char line[1024];
    va_list args;
    va_start(args, format);
    std::vsnprintf(line, sizeof(line), format, args);
    va_end(args);
    out_ << line << '\n';
  }
  void Close() {
    out_.close();
    if (!out_) throw WorkError(path_, "writing the truth file failed");
  }

 private:
  std::string path_;
  std::ofstream out_;
};

void WriteJson(const std::string& path, const json& j) {
  std::ofstream out(path);
  out << j.dump(2) << '\n';
  out.close();
  if (!out) throw WorkError(path, "cannot write the truth file");
}

// Writes a full-frame 8-bit matte holding `layer` (zero elsewhere) as PNG.
void WriteMatte(const std::string& path, const MatteLayer& layer, int width, int height,
                cv::Mat& scratch) {
  scratch.create(height, width, CV_8U);
  scratch.setTo(0);
  if (!layer.box.empty()) layer.values.copyTo(scratch(layer.box));
  static const std::vector<int> params = {cv::IMWRITE_PNG_COMPRESSION, 1, cv::IMWRITE_PNG_STRATEGY,
                                          cv::IMWRITE_PNG_STRATEGY_RLE};
  if (!cv::imwrite(path, scratch, params)) throw WorkError(path, "cannot write the matte PNG");
}

// The lowest image point of a subject's silhouette (largest y), from the
// primitives' contour generators; NaN when the subject is not in front of the camera.
struct LowestPoint {
  Eigen::Vector2d px{NAN, NAN};
  Eigen::Vector3d point_in_ground{NAN, NAN, NAN};
};

LowestPoint SilhouetteLowest(const SynthCamera& cam, const std::vector<Primitive>& prims,
                             int subject) {
  LowestPoint best;
  const Eigen::Vector3d eye = cam.CentreInGround();
  double best_y = -1e30;
  for (const Primitive& p : prims) {
    if (p.subject != subject || p.slice != 0) continue;
    for (const Eigen::Vector3d& q : p.ContourPoints(eye, 96)) {
      if (q.z() < 0) continue;  // below the floor: never drawn
      const Eigen::Vector2d px = cam.ProjectGround(q);
      if (!std::isfinite(px.y())) continue;
      if (px.y() > best_y) {
        best_y = px.y();
        best.px = px;
        best.point_in_ground = q;
      }
    }
  }
  return best;
}

// Pixels of subject b's silhouette (alpha > 0) on or next to (8-neighbours) subject a's: > 0 when
// the two silhouettes overlap or touch in the image, so that a keyer sees one blob where a
// perfect one would (docs/synth.md, overlaps.csv).
int SilhouettesShared(const MatteLayer& a, const MatteLayer& b) {
  if (a.box.empty() || b.box.empty()) return 0;
  const cv::Rect grown(a.box.x - 1, a.box.y - 1, a.box.width + 2, a.box.height + 2);
  const cv::Rect both = grown & b.box;
  if (both.empty()) return 0;
  int shared = 0;
  for (int y = both.y; y < both.y + both.height; ++y) {
    for (int x = both.x; x < both.x + both.width; ++x) {
      if (b.values.at<uint8_t>(y - b.box.y, x - b.box.x) == 0) continue;
      bool near = false;
      for (int dy = -1; dy <= 1 && !near; ++dy) {
        const int ay = y + dy - a.box.y;
        if (ay < 0 || ay >= a.box.height) continue;
        for (int dx = -1; dx <= 1 && !near; ++dx) {
          const int ax = x + dx - a.box.x;
          near = ax >= 0 && ax < a.box.width && a.values.at<uint8_t>(ay, ax) > 0;
        }
      }
      shared += near ? 1 : 0;
    }
  }
  return shared;
}

struct CameraWork {
  const SynthCamera* camera = nullptr;
  std::unique_ptr<CameraRenderer> renderer;
  std::unique_ptr<Sensor> sensor;
  std::unique_ptr<CsvFile> views;
  std::unique_ptr<CsvFile> overlaps;  // several subjects: per pair, whether the silhouettes touch
  std::unique_ptr<CsvFile> joints;    // figures
  std::unique_ptr<CsvFile> corners;   // calibration
  fs::path truth_dir;
  double render_s = 0, sensor_s = 0, encode_s = 0, truth_s = 0;
  CameraImage image;
  cv::Mat scratch;
};

}  // namespace

int SynthOptions::frames() const {
  return std::max(1, static_cast<int>(std::lround(seconds * fps)));
}

bool SynthOptions::IsValid(std::string* why) const {
  OptionProblems check(why);
  // The director's fields by the director's ranges; then, for values it takes, the session's
  // narrower ones (each field named once).
  std::string part;
  check.Nested(DirectorOptions::IsValid(&part), "", part);
  if (subjects >= 0 && subjects <= 64) {
    check(subjects <= 8, "subjects",
          "a session renders at most 8 subjects, got " + std::to_string(subjects));
  }
  if (std::isfinite(fps) && fps > 0) {
    check(fps >= 1 && fps <= 240, "fps",
          "a session runs at 1..240 frames per second, got " + OptionProblems::Num(fps));
  }
  check(!out_dir.empty(), "out_dir", "a session folder is needed");
  check.Within(seconds, AboveUpTo(0, 3600), "seconds", "0 < seconds <= 3600");
  const bool bayer = pixel_format == PixelFormat::kBayerRG8;
  const bool width_ok = width >= 64 && width <= 4096, height_ok = height >= 48 && height <= 4096;
  check(width_ok, "width", "expected 64..4096 pixels, got " + std::to_string(width));
  check(!width_ok || !bayer || width % 2 == 0, "width",
        "bayer_rg8 needs an even width, got " + std::to_string(width));
  check(height_ok, "height", "expected 48..4096 pixels, got " + std::to_string(height));
  check(!height_ok || !bayer || height % 2 == 0, "height",
        "bayer_rg8 needs an even height, got " + std::to_string(height));
  check.Within(cameras, Between(1, 8), "cameras", "1..8");
  check(pixel_format == PixelFormat::kRGB8 || pixel_format == PixelFormat::kBGR8 || bayer ||
            pixel_format == PixelFormat::kMono8,
        "pixel_format",
        "expected rgb8, bgr8, bayer_rg8 or mono8, got " + PixelFormatName(pixel_format));
  check.Within(noise, Between(0, 10), "noise", "0..10");
  check.Within(threads, Between(1, 64), "threads", "1..64");
  check(!(kind == SynthKind::kAnimal && studio == StudioKind::kStage), "studio",
        "animals live in the enclosure");
  check(!(kind == SynthKind::kFly && studio == StudioKind::kStage), "studio",
        "flies live in the enclosure");
  check(!(kind == SynthKind::kFigure && studio == StudioKind::kEnclosure), "studio",
        "figures perform on the stage");
  check(!(view == CameraView::kOverhead &&
          (kind == SynthKind::kFigure || studio == StudioKind::kStage)),
        "view", "cameras look down from overhead in the enclosure only");
  check(FindRecordingCodec(codec) != nullptr, "codec",
        "unknown codec '" + codec + "' (expected " + RecordingCodecNames() + ")");
  check.Within(empty_lead_in_s, AtLeast(0), "empty_lead_in_s", "seconds >= 0");
  return check.ok();
}

SynthSummary RenderStudioSession(const SynthOptions& o) {
  if (std::string why; !o.IsValid(&why)) throw InputError("synth options", why);
  const auto t_start = Clock::now();
  const double cpu_start = ProcessCpuS();
  auto log = Log("synth");

  const StudioKind studio_kind =
      o.studio.value_or(o.kind == SynthKind::kFigure ? StudioKind::kStage : StudioKind::kEnclosure);
  const Studio studio = MakeStudio(studio_kind, o.seed);
  const std::vector<SynthCamera> cameras =
      MakeCameras(studio, o.cameras, o.width, o.height, o.seed, o.view);
  std::unique_ptr<Director> director;
  switch (o.kind) {
    case SynthKind::kAnimal:
      director = MakeAnimalDirector(studio, cameras, o);
      break;
    case SynthKind::kCalibration:
      director = MakeCalibrationDirector(studio, cameras, o, o.frames() / o.fps);
      break;
    case SynthKind::kFigure:
      director = MakeFigureDirector(studio, cameras, o);
      break;
    case SynthKind::kFly:
      director = MakeFlyDirector(studio, o);
      break;
  }

  // The recorded session.
  RecordingOptions rec;
  rec.synthetic = true;
  rec.codec = o.codec;
  rec.flush_interval_ms = 1000;
  SessionWriter writer(
      o.out_dir,
      "synth-" + std::string(TextOf(o.kind, kSynthKindTexts)) + "-seed" + std::to_string(o.seed),
      rec);
  const fs::path truth = fs::path(o.out_dir) / "truth";
  std::error_code ec;
  fs::create_directories(truth, ec);
  if (ec) throw WorkError(truth.string(), "cannot create the truth folder: " + ec.message());

  std::vector<CameraWork> work(cameras.size());
  const int subjects = director->subjects();
  const auto joint_names = director->joint_names();
  const std::vector<BoardSpec>& board_specs = director->board_specs();
  for (size_t c = 0; c < cameras.size(); ++c) {
    const SynthCamera& cam = cameras[c];
    const CameraModel model(cam.lensmodel, cam.intrinsics, cam.width, cam.height,
                            cam.cam_from_ground);
    const int index = writer.AddCamera({.name = cam.name,
                                        .width = cam.width,
                                        .height = cam.height,
                                        .format = o.pixel_format,
                                        .fps = o.fps},
                                       &model);
    if (index != static_cast<int>(c)) throw WorkError(o.out_dir, "camera index mismatch");
    model.Write((truth / (cam.name + ".cameramodel")).string());
    CameraWork& w = work[c];
    w.camera = &cam;
    w.renderer = std::make_unique<CameraRenderer>(cam, studio);
    // The empty enclosure as the camera sees it without sensor noise (what `plate` estimates).
    if (!cv::imwrite((truth / (cam.name + "_plate.png")).string(), w.renderer->clean_plate())) {
      throw WorkError((truth / (cam.name + "_plate.png")).string(), "cannot write the clean plate");
    }
    w.sensor = std::make_unique<Sensor>(o.seed, static_cast<int>(c), o.noise);
    w.truth_dir = truth / cam.name;
    fs::create_directories(w.truth_dir / "shadow", ec);
    for (int k = 0; k < subjects; ++k)
      fs::create_directories(w.truth_dir / ("alpha_s" + std::to_string(k)), ec);
    if (ec)
      throw WorkError(w.truth_dir.string(), "cannot create the truth folder: " + ec.message());
    w.views = std::make_unique<CsvFile>((w.truth_dir / "views.csv").string(),
                                        "frame,subject,visible_px,unoccluded_px,box_x,box_y,box_w,"
                                        "box_h,lowest_x,lowest_y,lowest_gx,lowest_gy,"
                                        "lowest_gz,lowest_ray_gx,lowest_ray_gy,root_x,root_y,"
                                        "contact_x,contact_y,contact_ray_gx,contact_ray_gy");
    if (subjects > 1) {
      w.overlaps = std::make_unique<CsvFile>((w.truth_dir / "overlaps.csv").string(),
                                             "frame,subject_a,subject_b,touching,shared_px");
    }
    if (!joint_names.empty()) {
      w.joints = std::make_unique<CsvFile>((w.truth_dir / "joints.csv").string(),
                                           "frame,subject,joint,name,x,y");
    }
    if (!board_specs.empty()) {
      w.corners = std::make_unique<CsvFile>((w.truth_dir / "corners.csv").string(),
                                            "frame,board,corner,x,y,in_view");
    }
  }

  // Camera-independent truth.
  const GroundPolygon& floor = studio.floor;
  json floor_json;
  floor_json["frame"] = "ground (z up, z = 0 the floor, metres)";
  floor_json["polygon"] = json::array();
  for (const auto& v : floor.vertices()) floor_json["polygon"].push_back({v.x(), v.y()});
  floor_json["walls"] = json::array();
  for (int wi : studio.green_walls) {
    const Quad& q = studio.quads[static_cast<size_t>(wi)];
    const Eigen::Vector3d a = q.origin, b = q.origin + (q.u.z() == 0 ? q.u : q.v);
    floor_json["walls"].push_back(
        {{"from", {a.x(), a.y()}}, {"to", {b.x(), b.y()}}, {"height_m", studio.wall_height}});
  }
  WriteJson((truth / "floor.json").string(), floor_json);
  CsvFile subjects_csv(
      (truth / "subjects.csv").string(),
      "frame,timestamp_ns,subject,kind,x,y,heading_rad,speed_mps,gait_phase,pose,touches_wall,"
      "leaves_floor,height_m");
  std::unique_ptr<CsvFile> boards_csv;
  if (!board_specs.empty()) {
    json boards;
    boards["frame"] =
        "board frame (OpenCV's): origin at the top-left corner of the checkered area, x along the "
        "columns, "
        "y along the rows, z into the board (the print is seen from -z); inner corner c "
        "(row-major, "
        "squares_x - 1 per row) at ((col + 1) * square_m, (row + 1) * square_m, 0); the top-left "
        "square is black; "
        "ChArUco corner ids are these inner-corner indices";
    boards["boards"] = json::array();
    for (size_t b = 0; b < board_specs.size(); ++b) {
      const BoardSpec& spec = board_specs[b];
      json j = {{"board", b},
                {"kind", spec.Name()},
                {"squares_x", spec.squares_x},
                {"squares_y", spec.squares_y},
                {"square_m", spec.square_m},
                {"margin_m", spec.margin_m},
                {"inner_corners", {spec.squares_x - 1, spec.squares_y - 1}}};
      if (spec.kind == BoardKind::kCharuco) {
        j["marker_m"] = spec.marker_m;
        j["dictionary"] = spec.dictionary;
      }
      boards["boards"].push_back(j);
    }
    boards["poses"] =
        "board_poses.csv: ground_from_board as mrcal rt (Rodrigues r, then t) per frame and board";
    WriteJson((truth / "boards.json").string(), boards);
    boards_csv = std::make_unique<CsvFile>((truth / "board_poses.csv").string(),
                                           "frame,timestamp_ns,board,placement,rx,ry,rz,tx,ty,tz");
  }
  std::unique_ptr<CsvFile> joints_csv;
  if (!joint_names.empty()) {
    joints_csv = std::make_unique<CsvFile>((truth / "joints.csv").string(),
                                           "frame,subject,joint,name,x,y,z");
  }

  SynthSummary summary;
  summary.out_dir = o.out_dir;
  summary.frames = o.frames();
  summary.cameras = static_cast<int>(cameras.size());
  summary.subjects = subjects;
  summary.fps = o.fps;

  std::vector<FrameSnapshot> chunk(kChunkFrames);
  std::vector<int64_t> stamps(kChunkFrames);
  const int n_threads = std::min<int>(o.threads, static_cast<int>(cameras.size()));
  std::mutex error_mutex;
  std::string worker_error;

  // Renders, encodes and writes the truth of frames [first, first + count) for one camera.
  auto render_camera = [&](size_t c, int first, int count) {
    CameraWork& w = work[c];
    const SynthCamera& cam = *w.camera;
    for (int i = 0; i < count; ++i) {
      const int frame = first + i;
      const FrameSnapshot& snap = chunk[static_cast<size_t>(i)];
      double t0 = ThreadCpuS();
      w.renderer->Render(snap.scene, &w.image);
      w.render_s += (ThreadCpuS() - t0);
      t0 = ThreadCpuS();
      std::vector<uint8_t> bytes =
          w.sensor->Capture(w.image.bgr, o.pixel_format, static_cast<uint64_t>(frame));
      w.sensor_s += (ThreadCpuS() - t0);
      t0 = ThreadCpuS();
      Frame f = Frame::Owned(o.pixel_format, cam.width, cam.height, std::move(bytes));
      f.camera = static_cast<int>(c);
      f.sequence = static_cast<uint64_t>(frame);
      f.timestamp_ns = stamps[static_cast<size_t>(i)];
      writer.Write(f);
      w.encode_s += (ThreadCpuS() - t0);
      t0 = ThreadCpuS();
      if (o.write_mattes) {
        const std::string name = FrameName(frame);
        WriteMatte((w.truth_dir / "shadow" / name).string(), w.image.shadow, cam.width, cam.height,
                   w.scratch);
        for (int k = 0; k < subjects; ++k) {
          WriteMatte((w.truth_dir / ("alpha_s" + std::to_string(k)) / name).string(),
                     w.image.alpha[static_cast<size_t>(k)], cam.width, cam.height, w.scratch);
        }
      }
      for (int k = 0; k < subjects; ++k) {
        const SubjectTruth& st = snap.subjects[static_cast<size_t>(k)];
        const MatteLayer& layer = w.image.alpha[static_cast<size_t>(k)];
        const LowestPoint low = SilhouetteLowest(cam, snap.scene.primitives, k);
        Eigen::Vector2d ray_ground(NAN, NAN);
        if (std::isfinite(low.px.x())) {
          const auto hit =
              IntersectGround({cam.CentreInGround(), cam.RayDirectionInGround(low.px)});
          if (hit) ray_ground = hit->head<2>();
        }
        const Eigen::Vector2d root_px = cam.ProjectGround({st.position.x(), st.position.y(), 0.0});
        // The contact point as the pipeline defines it (core/contact_point.h), from the true alpha.
        Eigen::Vector2d contact_px(NAN, NAN), contact_ground(NAN, NAN);
        cv::Point2d contact;
        if (!layer.box.empty() && ContactPoint(layer.values, &contact)) {
          contact_px = {layer.box.x + contact.x, layer.box.y + contact.y};
          const auto hit =
              IntersectGround({cam.CentreInGround(), cam.RayDirectionInGround(contact_px)});
          if (hit) contact_ground = hit->head<2>();
        }
        w.views->Row(
            "%d,%d,%.4f,%.4f,%d,%d,%d,%d,%.4f,%.4f,%.6f,%.6f,%.6f,%.6f,%.6f,%.4f,%.4f,"
            "%.4f,%.4f,%.6f,%.6f",
            frame, k, w.image.visible_px[static_cast<size_t>(k)],
            w.image.unoccluded_px[static_cast<size_t>(k)], layer.box.x, layer.box.y,
            layer.box.width, layer.box.height, low.px.x(), low.px.y(), low.point_in_ground.x(),
            low.point_in_ground.y(), low.point_in_ground.z(), ray_ground.x(), ray_ground.y(),
            root_px.x(), root_px.y(), contact_px.x(), contact_px.y(), contact_ground.x(),
            contact_ground.y());
        if (w.joints) {
          for (size_t j = 0; j < st.joints.size(); ++j) {
            const Eigen::Vector2d px = cam.ProjectGround(st.joints[j]);
            w.joints->Row("%d,%d,%zu,%s,%.4f,%.4f", frame, k, j, joint_names[j].c_str(), px.x(),
                          px.y());
          }
        }
      }
      if (w.overlaps) {
        for (int a = 0; a < subjects; ++a) {
          for (int b = a + 1; b < subjects; ++b) {
            const int shared = SilhouettesShared(w.image.alpha[static_cast<size_t>(a)],
                                                 w.image.alpha[static_cast<size_t>(b)]);
            w.overlaps->Row("%d,%d,%d,%d,%d", frame, a, b, shared > 0 ? 1 : 0, shared);
          }
        }
      }
      if (w.corners) {
        const Eigen::Vector3d eye = cam.CentreInGround();
        for (const BoardTruth& bt : snap.boards) {
          const BoardSpec& spec = board_specs[static_cast<size_t>(bt.board)];
          const Eigen::Vector3d eye_b = bt.ground_from_board.Inverse() * eye;
          const auto corners = spec.InnerCorners();
          for (size_t i = 0; i < corners.size(); ++i) {
            const Eigen::Vector3d p = bt.ground_from_board * corners[i];
            const Eigen::Vector2d px = cam.ProjectGround(p);
            bool in_view = eye_b.z() < 0 && std::isfinite(px.x()) && px.x() >= 0 && px.y() >= 0 &&
                           px.x() <= cam.width - 1 && px.y() <= cam.height - 1;
            if (in_view) {  // not hidden behind a wall
              const double dist = (p - eye).norm();
              in_view = studio.Trace(eye, (p - eye) / dist).t > dist - 1e-4;
            }
            w.corners->Row("%d,%d,%zu,%.4f,%.4f,%d", frame, bt.board, i, px.x(), px.y(),
                           in_view ? 1 : 0);
          }
        }
      }
      w.truth_s += (ThreadCpuS() - t0);
    }
  };

  for (int first = 0; first < summary.frames; first += kChunkFrames) {
    const int count = std::min(kChunkFrames, summary.frames - first);
    const double t0 = ThreadCpuS();
    for (int i = 0; i < count; ++i) {
      const int frame = first + i;
      const double time_s = frame / o.fps;
      stamps[static_cast<size_t>(i)] = static_cast<int64_t>(std::llround(frame * 1e9 / o.fps));
      FrameSnapshot& snap = chunk[static_cast<size_t>(i)];
      director->Frame(time_s, &snap);
      if (time_s < o.empty_lead_in_s) {  // the empty enclosure: subjects not yet placed
        snap.scene.primitives.clear();
        for (SubjectTruth& st : snap.subjects) st.pose = "absent";
      }
      for (size_t k = 0; k < snap.subjects.size(); ++k) {
        const SubjectTruth& st = snap.subjects[k];
        subjects_csv.Row("%d,%lld,%zu,%s,%.6f,%.6f,%.6f,%.6f,%.6f,%s,%d,%d,%.6f", frame,
                         static_cast<long long>(stamps[static_cast<size_t>(i)]), k, st.kind.c_str(),
                         st.position.x(), st.position.y(), st.heading_rad, st.speed_mps,
                         st.gait_phase, st.pose.c_str(), st.touches_wall ? 1 : 0,
                         st.leaves_floor ? 1 : 0, st.height_m);
        summary.pose_frames[st.pose] += 1;
        if (st.touches_wall) ++summary.wall_touch_frames;
        if (joints_csv) {
          for (size_t j = 0; j < st.joints.size(); ++j) {
            const auto& p = st.joints[j];
            joints_csv->Row("%d,%zu,%zu,%s,%.6f,%.6f,%.6f", frame, k, j, joint_names[j].c_str(),
                            p.x(), p.y(), p.z());
          }
        }
      }
    }
    if (boards_csv) {
      for (int i = 0; i < count; ++i) {
        for (const BoardTruth& bt : chunk[static_cast<size_t>(i)].boards) {
          double rt[6];
          bt.ground_from_board.ToRt(rt);
          boards_csv->Row("%d,%lld,%d,%s,%.9f,%.9f,%.9f,%.9f,%.9f,%.9f", first + i,
                          static_cast<long long>(stamps[static_cast<size_t>(i)]), bt.board,
                          bt.placement.c_str(), rt[0], rt[1], rt[2], rt[3], rt[4], rt[5]);
        }
      }
    }
    summary.simulate_s += ThreadCpuS() - t0;
    if (n_threads <= 1) {
      for (size_t c = 0; c < cameras.size(); ++c) render_camera(c, first, count);
    } else {
      std::vector<std::thread> pool;
      pool.reserve(n_threads);
      for (int t = 0; t < n_threads; ++t) {
        pool.emplace_back([&, t] {
          try {
            for (size_t c = static_cast<size_t>(t); c < cameras.size();
                 c += static_cast<size_t>(n_threads)) {
              render_camera(c, first, count);
            }
          } catch (const std::exception& e) {
            std::lock_guard<std::mutex> lock(error_mutex);
            if (worker_error.empty()) worker_error = e.what();
          }
        });
      }
      for (auto& th : pool) th.join();
      if (!worker_error.empty()) throw WorkError(worker_error);
    }
  }

  const double t_close = ThreadCpuS();
  writer.Close();
  summary.encode_s += ThreadCpuS() - t_close;
  subjects_csv.Close();
  if (joints_csv) joints_csv->Close();
  if (boards_csv) boards_csv->Close();
  for (auto& w : work) {
    w.views->Close();
    if (w.overlaps) w.overlaps->Close();
    if (w.joints) w.joints->Close();
    if (w.corners) w.corners->Close();
    summary.render_s += w.render_s;
    summary.sensor_s += w.sensor_s;
    summary.encode_s += w.encode_s;
    summary.truth_s += w.truth_s;
  }

  json t = {{"format_version", kTruthVersion},
            {"kind", TextOf(o.kind, kSynthKindTexts)},
            {"studio", StudioKindName(studio.kind)},
            {"view", TextOf(o.view, kCameraViewTexts)},
            {"seed", o.seed},
            {"fps", o.fps},
            {"frames", summary.frames},
            {"width", o.width},
            {"height", o.height},
            {"pixel_format", PixelFormatName(o.pixel_format)},
            {"noise", o.noise},
            {"motion_blur", o.motion_blur},
            {"crossing", o.crossing},
            {"timestamp_ns", "round(frame * 1e9 / fps), the same on every camera"},
            {"floor", floor_json},
            {"cameras", json::array()}};
  for (const auto& cam : cameras) {
    t["cameras"].push_back(
        {{"name", cam.name},
         {"model", cam.name + ".cameramodel"},
         {"centre_in_ground",
          {cam.CentreInGround().x(), cam.CentreInGround().y(), cam.CentreInGround().z()}}});
  }
  t["subjects"] = json::parse(director->SubjectsJson());
  if (!joint_names.empty()) t["joint_names"] = joint_names;
  t["files"] = {{"subjects", "subjects.csv"},
                {"views", "<camera>/views.csv"},
                {"overlaps", subjects > 1 ? "<camera>/overlaps.csv" : ""},
                {"alpha", o.write_mattes ? "<camera>/alpha_s<subject>/<frame:06d>.png" : ""},
                {"shadow", o.write_mattes ? "<camera>/shadow/<frame:06d>.png" : ""}};
  if (!board_specs.empty()) {
    t["files"]["boards"] = "boards.json";
    t["files"]["board_poses"] = "board_poses.csv";
    t["files"]["corners"] = "<camera>/corners.csv";
  }
  if (!joint_names.empty()) {
    t["files"]["joints"] = "joints.csv";
    t["files"]["joints_2d"] = "<camera>/joints.csv";
  }
  WriteJson((truth / "truth.json").string(), t);

  summary.wall_s = Since(t_start);
  summary.cpu_s = ProcessCpuS() - cpu_start;
  log->info(
      "{}: {} frames x {} camera(s) of a {} session in {:.2f} s wall, {:.2f} s CPU ({:.2f} "
      "camera-seconds "
      "per CPU-second)",
      o.out_dir, summary.frames, summary.cameras, TextOf(o.kind, kSynthKindTexts), summary.wall_s,
      summary.cpu_s, summary.CpuRealTimeFactor());
  return summary;
}

}  // namespace ss::synth
