// Calibration sessions: the session time is split into one segment per camera
// and board (the board held before that camera, moving through poses that it
// holds still for a moment), with several cameras one segment of the chessboard
// held where every camera sees it (for a joint solve of the rig, calib/joint.h),
// and a last segment with both boards flat on the floor.
#include <algorithm>
#include <cmath>
#include <string>

#include <Eigen/Geometry>
#include <nlohmann/json.hpp>

#include "core/error.h"
#include "synth/angles.h"
#include "synth/directors.h"
#include "synth/random.h"

namespace ss::synth {
namespace {

constexpr double kPoseSeconds = 0.8;  // one pose: move for 60 %, then hold still
// With several cameras every pose is held still longer, about 1 s as an operator would: their
// wizards share the cores (each sees fewer frames), and before every camera at once each must
// see the board still over spans that overlap in time (SimultaneousObservations). (Held 0.6 s,
// a loaded machine's wizards caught few of them: 3 places both saw in two loops of 90 s.)
constexpr double kRigPoseSeconds = 1.6;
constexpr double kRigMoveShare = 0.4;

// A segment of `seconds` at `pose_s` a pose: the poses it moves through.
int PoseCount(double seconds, double pose_s) {
  return std::max(2, static_cast<int>(std::ceil(seconds / pose_s)) + 1);
}

// A board's frame lying print up: x along ground x, y along -ground y.
Eigen::Matrix3d FaceUp() { return Eigen::Vector3d(1, -1, -1).asDiagonal(); }

Rigid3 Interpolate(const Rigid3& a, const Rigid3& b, double s) {
  const Eigen::Quaterniond qa(a.rotation), qb(b.rotation);
  Rigid3 out;
  out.rotation = qa.slerp(s, qb).toRotationMatrix();
  out.translation = a.translation + s * (b.translation - a.translation);
  return out;
}

struct Segment {
  double start_s = 0, end_s = 0;
  int board = 0;              // index into specs
  int camera = -1;            // kFloor, kRig, or the camera the board is held before
  std::vector<Rigid3> poses;  // ground_from_board, one per pose
  double move_share = 0.6;    // of each pose's time; the rest it holds still
};
constexpr int kFloor = -1, kRig = -2;

class CalibrationDirector : public Director {
 public:
  CalibrationDirector(const Studio& studio, const std::vector<SynthCamera>& cameras,
                      const DirectorOptions& options, double seconds)
      : studio_(studio), cameras_(cameras) {
    const bool stage = studio.kind == StudioKind::kStage;
    specs_ = {ChessboardFor(stage), CharucoFor(stage)};
    for (const auto& s : specs_) textures_.push_back(std::make_unique<BoardTexture>(s));
    Rng rng(StreamSeed(options.seed, "calibration-boards"));
    // Segments: camera 0 chessboard, camera 0 ChArUco, camera 1 ..., with several cameras the
    // chessboard before all of them (twice a camera segment's time), then the floor (one pose
    // slot).
    const bool rig = cameras.size() > 1;
    const int hand_segments = 2 * static_cast<int>(cameras.size()) + (rig ? 2 : 0);
    const double floor_s = std::max(seconds * 0.1, std::min(1.0, seconds / (hand_segments + 1)));
    const double hand_s = (seconds - floor_s) / hand_segments;
    double t = 0;
    for (size_t c = 0; c < cameras.size(); ++c) {
      for (int b = 0; b < 2; ++b) {
        Segment seg;
        seg.start_s = t;
        seg.end_s = t + hand_s;
        seg.board = b;
        seg.camera = static_cast<int>(c);
        if (rig) seg.move_share = kRigMoveShare;
        const int poses = PoseCount(hand_s, rig ? kRigPoseSeconds : kPoseSeconds);
        // With several cameras each has a shorter time: its poses go round the image's nine
        // regions, so that the views it has time to capture cover it.
        for (int p = 0; p < poses; ++p) {
          seg.poses.push_back(HeldPose(cameras[c], specs_[b], rng, rig ? (p * 4 + b) % 9 : -1));
        }
        segments_.push_back(seg);
        t += hand_s;
      }
    }
    if (rig) {
      Segment seg;
      seg.start_s = t;
      seg.end_s = t + 2 * hand_s;
      seg.camera = kRig;
      seg.move_share = kRigMoveShare;
      const int poses = PoseCount(2 * hand_s, kRigPoseSeconds);
      for (int p = 0; p < poses; ++p) seg.poses.push_back(RigPose(studio, cameras, specs_[0], rng));
      segments_.push_back(seg);
      t += 2 * hand_s;
    }
    // On the floor: the chessboard's frame at the ground origin (x along ground x,
    // y along -ground y, the print facing up), the ChArUco board beside it.
    Segment floor;
    floor.start_s = t;
    floor.end_s = seconds + 1.0;
    floor.camera = kFloor;
    segments_.push_back(floor);
    const BoardSpec& chess = specs_[0];
    floor_poses_.resize(2);
    floor_poses_[0].rotation = FaceUp();
    floor_poses_[0].translation =
        Eigen::Vector3d(-0.5 * chess.width_m(), 0.5 * chess.height_m(), 0.001);
    const BoardSpec& charuco = specs_[1];
    const double gap = chess.margin_m + charuco.margin_m + 0.02;
    floor_poses_[1].rotation = FaceUp();
    const double x1 = -0.5 * chess.width_m() + chess.width_m() + gap;
    floor_poses_[1].translation = Eigen::Vector3d(x1, 0.5 * charuco.height_m(), 0.001);
    if (x1 + charuco.width_m() > studio.half_x - 0.01) {  // not beside it: in front of it
      floor_poses_[1].translation =
          Eigen::Vector3d(-0.5 * charuco.width_m(), -0.5 * chess.height_m() - gap, 0.001);
    }
  }

  int subjects() const override { return 0; }
  const std::vector<BoardSpec>& board_specs() const override { return specs_; }

  void Frame(double time_s, FrameSnapshot* out) override {
    StartFrame(out, 0, false);
    const Segment* seg = &segments_.back();
    for (const auto& s : segments_) {
      if (time_s >= s.start_s && time_s < s.end_s) {
        seg = &s;
        break;
      }
    }
    if (seg->camera == kFloor) {
      for (int b = 0; b < 2; ++b) Add(b, floor_poses_[static_cast<size_t>(b)], "floor", out);
      return;
    }
    // Pose p is reached at start + (p + move_share) * step and held until start + (p + 1) * step.
    const double step = (seg->end_s - seg->start_s) / static_cast<double>(seg->poses.size() - 1);
    const double u = (time_s - seg->start_s) / step;
    const int p =
        std::min(static_cast<int>(seg->poses.size()) - 2, static_cast<int>(std::floor(u)));
    const double s = Smooth((u - p) / seg->move_share);
    Add(seg->board,
        Interpolate(seg->poses[static_cast<size_t>(p)], seg->poses[static_cast<size_t>(p) + 1], s),
        seg->camera == kRig ? "rig" : "camera:" + cameras_[static_cast<size_t>(seg->camera)].name,
        out);
  }

  std::string SubjectsJson() const override { return "[]"; }

 private:
  // The smallest margin, in pixels, of the board's outer corners inside `cam`'s image (negative:
  // outside it; -1e9: a corner behind the camera).
  static double Margin(const SynthCamera& cam, const BoardSpec& spec,
                       const Rigid3& ground_from_board) {
    double margin = 1e9;
    for (double bx : {0.0, spec.width_m()}) {
      for (double by : {0.0, spec.height_m()}) {
        const Eigen::Vector3d in_cam =
            cam.cam_from_ground * (ground_from_board * Eigen::Vector3d(bx, by, 0));
        if (in_cam.z() <= 0) return -1e9;
        const Eigen::Vector2d px = cam.lens.Project(in_cam);
        margin = std::min({margin, px.x(), px.y(), cam.width - px.x(), cam.height - px.y()});
      }
    }
    return margin;
  }

  // A pose of `spec` before `cam`: the print facing the camera, tilted up to
  // 40 degrees, filling 35-65 % of the image width, anywhere in the view (`region` -1) or
  // towards one of its nine regions (0..8, row by row; 30-45 % outside the middle one). Drawn
  // again (up to 50 times, else the draw that came nearest) until the board is seen at most
  // 50 degrees off its normal and lies wholly in the image, 3 % of its width from the edges:
  // the two tilts and an edge's ray added up to ~60 degrees, where OpenCV's detector finds no
  // board, and a rig camera's region (each held once, at one pose) then stayed empty (the
  // bottom-left of seed 5's cam0, and its wizard's coverage check with it).
  static Rigid3 HeldPose(const SynthCamera& cam, const BoardSpec& spec, Rng& rng, int region) {
    Rigid3 best;
    double best_score = -1e18;
    for (int attempt = 0; attempt < 50 && best_score < 0; ++attempt) {
      const Rigid3 pose = DrawHeldPose(cam, spec, rng, region);
      const Rigid3 cam_from_board = cam.cam_from_ground * pose;
      const double margin = Margin(cam, spec, pose);
      const Eigen::Vector3d centre =
          cam_from_board * Eigen::Vector3d(0.5 * spec.width_m(), 0.5 * spec.height_m(), 0);
      const double off_normal_deg =
          std::acos(std::abs(cam_from_board.rotation.col(2).dot(centre.normalized()))) / kDeg;
      // Negative until both hold: how far from holding they are, in pixels and degrees.
      const double score =
          std::min(margin - 0.03 * cam.width, 0.0) + 10.0 * std::min(50.0 - off_normal_deg, 0.0);
      if (score > best_score) {
        best_score = score;
        best = pose;
      }
    }
    return best;
  }

  static Rigid3 DrawHeldPose(const SynthCamera& cam, const BoardSpec& spec, Rng& rng, int region) {
    double fill = rng.Uniform(0.35, 0.65);
    // Off the middle a smaller board (30-45 %) leaves room to reach the image's edges.
    if (region >= 0 && region != 4) fill = 0.3 + 0.5 * (fill - 0.35);
    const double depth = cam.lens.fx() * spec.width_m() / (fill * cam.width);
    // Where the board's centre appears: within the middle of the image, leaving room for the board.
    const double room_x = std::max(0.0, 0.5 - 0.5 * fill - 0.06),
                 room_y = std::max(0.0, 0.5 - 0.5 * fill * 1.2 - 0.06);
    Eigen::Vector2d at(rng.Uniform(-room_x, room_x), rng.Uniform(-room_y, room_y));
    if (region >= 0) {  // the region's third of the room, the draw kept as jitter within it
      const int column = region % 3 - 1, row = region / 3 - 1;  // -1, 0 or 1 each
      at.x() = room_x * column * 2.0 / 3 + at.x() / 3;
      at.y() = room_y * row * 2.0 / 3 + at.y() / 3;
    }
    const Eigen::Vector2d px(cam.width * (0.5 + at.x()), cam.height * (0.5 + at.y()));
    const Eigen::Vector3d centre_in_cam =
        cam.lens.Unproject(px) / cam.lens.Unproject(px).z() * depth;
    const Eigen::Matrix3d tilt =
        (Eigen::AngleAxisd(rng.Uniform(-40, 40) * kDeg, Eigen::Vector3d::UnitX()) *
         Eigen::AngleAxisd(rng.Uniform(-40, 40) * kDeg, Eigen::Vector3d::UnitY()) *
         Eigen::AngleAxisd(rng.Uniform(-20, 20) * kDeg, Eigen::Vector3d::UnitZ()))
            .toRotationMatrix();
    Rigid3 cam_from_board;
    cam_from_board.rotation = tilt;
    cam_from_board.translation =
        centre_in_cam - tilt * Eigen::Vector3d(0.5 * spec.width_m(), 0.5 * spec.height_m(), 0);
    return cam.cam_from_ground.Inverse() * cam_from_board;
  }

  // A pose of `spec` that every camera sees whole, its print facing each of them at most 65
  // degrees off: above the middle of the floor, the print up (enclosure) or towards the cameras
  // (stage), tilted up to 25 degrees and turned about its normal.
  static Rigid3 RigPose(const Studio& studio, const std::vector<SynthCamera>& cameras,
                        const BoardSpec& spec, Rng& rng) {
    const bool stage = studio.kind == StudioKind::kStage;
    Eigen::Vector3d towards = Eigen::Vector3d::UnitZ();
    if (stage) {
      towards.setZero();
      for (const auto& cam : cameras) {
        towards += (cam.CentreInGround() - Eigen::Vector3d(0, 0, 0.9)).normalized();
      }
      towards.normalize();
    }
    const Eigen::Matrix3d to_cameras =
        Eigen::Quaterniond::FromTwoVectors(Eigen::Vector3d::UnitZ(), towards).toRotationMatrix();
    Rigid3 best;
    double best_margin = -1e9;
    for (int attempt = 0; attempt < 200; ++attempt) {
      const Eigen::Matrix3d r =
          to_cameras *
          (Eigen::AngleAxisd(rng.Uniform(-25, 25) * kDeg, Eigen::Vector3d::UnitX()) *
           Eigen::AngleAxisd(rng.Uniform(-25, 25) * kDeg, Eigen::Vector3d::UnitY()) *
           Eigen::AngleAxisd(rng.Uniform(-45, 45) * kDeg, Eigen::Vector3d::UnitZ()))
              .toRotationMatrix() *
          FaceUp();
      const Eigen::Vector3d centre =
          stage ? Eigen::Vector3d(rng.Uniform(-0.3, 0.3), rng.Uniform(-0.2, 0.2),
                                  rng.Uniform(0.8, 1.1))
                : Eigen::Vector3d(rng.Uniform(-0.12, 0.12), rng.Uniform(-0.08, 0.08),
                                  rng.Uniform(0.15, 0.3));
      const Rigid3 pose{
          r, centre - r * Eigen::Vector3d(0.5 * spec.width_m(), 0.5 * spec.height_m(), 0)};
      // The smallest margin, in pixels, of the board's corners inside every image; -1e9 when
      // a camera sees the print from too far off its normal.
      double margin = 1e9;
      const Eigen::Vector3d normal = r * Eigen::Vector3d(0, 0, -1);
      for (const auto& cam : cameras) {
        const Eigen::Vector3d to_cam = (cam.CentreInGround() - centre).normalized();
        if (normal.dot(to_cam) < std::cos(65 * kDeg)) margin = -1e9;
        margin = std::min(margin, Margin(cam, spec, pose));
      }
      if (margin > best_margin) {
        best_margin = margin;
        best = pose;
      }
      if (margin > 0.06 * cameras.front().width) break;
    }
    return best;
  }

  void Add(int board, const Rigid3& ground_from_board, const std::string& placement,
           FrameSnapshot* out) const {
    BoardInstance inst;
    inst.texture = textures_[static_cast<size_t>(board)].get();
    inst.ground_from_board = ground_from_board;
    out->scene.boards.push_back(inst);
    out->boards.push_back({board, ground_from_board, placement});
  }

  const Studio& studio_;
  std::vector<SynthCamera> cameras_;
  std::vector<BoardSpec> specs_;
  std::vector<std::unique_ptr<BoardTexture>> textures_;
  std::vector<Segment> segments_;
  std::vector<Rigid3> floor_poses_;
};

}  // namespace

std::unique_ptr<Director> MakeCalibrationDirector(const Studio& studio,
                                                  const std::vector<SynthCamera>& cameras,
                                                  const DirectorOptions& options, double seconds) {
  if (std::string why; !options.IsValid(&why)) throw InputError("director options", why);
  return std::make_unique<CalibrationDirector>(studio, cameras, options, seconds);
}

}  // namespace ss::synth
