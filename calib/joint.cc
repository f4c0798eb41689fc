#include "calib/joint.h"

#include <algorithm>
#include <cmath>
#include <map>

#include <Eigen/Geometry>

#include "calib/ground.h"
#include "core/error.h"

namespace ss::calib {

std::vector<BoardObservation> SimultaneousObservations(const std::vector<TimedView>& views,
                                                       double max_gap_s, int first_frame) {
  std::vector<const TimedView*> sorted;
  for (const auto& v : views) {
    if (v.view.accepted && std::isfinite(v.time_s)) sorted.push_back(&v);
  }
  std::stable_sort(sorted.begin(), sorted.end(),
                   [](const TimedView* x, const TimedView* y) { return x->time_s < y->time_s; });
  auto from = [](const TimedView* v) {
    return std::isfinite(v->start_s) ? std::min(v->start_s, v->time_s) : v->time_s;
  };
  std::vector<bool> used(sorted.size(), false);
  std::vector<BoardObservation> out;
  int frame = first_frame;
  for (size_t i = 0; i < sorted.size(); ++i) {
    if (used[i]) continue;
    // The instant of sorted[i]: of each other camera the unused view nearest in time whose span
    // meets sorted[i]'s (widened by max_gap_s).
    const TimedView* anchor = sorted[i];
    std::map<int, size_t> nearest;
    for (size_t j = i + 1; j < sorted.size(); ++j) {
      const TimedView* v = sorted[j];
      if (used[j] || v->camera == anchor->camera) continue;
      if (from(v) - max_gap_s > anchor->time_s) continue;  // sorted by time_s: v ends later
      auto [it, added] = nearest.emplace(v->camera, j);
      if (!added && v->time_s - anchor->time_s < sorted[it->second]->time_s - anchor->time_s)
        it->second = j;
    }
    if (nearest.empty()) continue;
    used[i] = true;
    nearest.emplace(anchor->camera, i);
    for (const auto& [camera, j] : nearest) {
      used[j] = true;
      const TimedView* v = sorted[j];
      out.push_back({camera, frame, v->view.source, v->view.ids, v->view.pixels});
    }
    ++frame;
  }
  return out;
}

JointRig SolveJointRig(const BoardSpec& board, const std::vector<SolveCamera>& cameras,
                       const std::vector<std::vector<BoardView>>& own,
                       const std::vector<BoardObservation>& simultaneous,
                       const SolveOptions& options) {
  JointRig rig;
  std::vector<BoardObservation> obs = simultaneous;
  int next = 0;
  std::map<int, int> shared;
  for (const auto& o : simultaneous) next = std::max(next, o.frame + 1), ++shared[o.frame];
  rig.shared_frames = static_cast<int>(shared.size());
  for (size_t c = 0; c < own.size() && c < cameras.size(); ++c) {
    for (const auto& v : own[c]) {
      if (v.accepted) obs.push_back({static_cast<int>(c), next++, v.source, v.ids, v.pixels});
    }
  }
  rig.solution = SolveBoards(board, cameras, obs, options);
  const SolveSummary& s = rig.solution;
  const size_t n = cameras.size();
  rig.views.assign(n, 0);
  std::vector<std::vector<double>> distances(n);
  for (size_t i = 0; i < obs.size(); ++i) {
    const auto c = static_cast<size_t>(obs[i].camera);
    ++rig.views[c];
    const Rigid3 cam_from_board = s.models[c].cam_from_ground() *
                                  s.ref_from_board[static_cast<size_t>(s.observation_frame[i])];
    distances[c].push_back(
        (cam_from_board * Eigen::Vector3d(board.squares_x * board.square_m / 2,
                                          board.squares_y * board.square_m / 2, 0))
            .norm());
  }
  for (size_t c = 0; c < n; ++c) {
    auto& d = distances[c];
    double median = 1.0;
    if (!d.empty()) {
      std::nth_element(d.begin(), d.begin() + static_cast<std::ptrdiff_t>(d.size() / 2), d.end());
      median = d[d.size() / 2];
    }
    rig.distance_m.push_back(median);
    const double w = cameras[c].width - 1, h = cameras[c].height - 1;
    const int cam = static_cast<int>(c);
    const double centre = ProjectionStdev(s, board, cam, {w / 2, h / 2}, median);
    double worst = centre;
    for (const Eigen::Vector2d& px : {Eigen::Vector2d(0, 0), Eigen::Vector2d(w, 0),
                                      Eigen::Vector2d(0, h), Eigen::Vector2d(w, h)}) {
      const double v = ProjectionStdev(s, board, cam, px, median);
      if (std::isfinite(v)) worst = std::isfinite(worst) ? std::max(worst, v) : v;
    }
    rig.stdev_px.push_back(centre);
    rig.stdev_worst.push_back(worst);
    double focal = NAN;
    const std::vector<double>& in = s.models[c].intrinsics();
    if (c < s.intrinsics_stdev.size() && s.intrinsics_stdev[c].size() >= 2 && in.size() >= 2) {
      focal = 1.96 *
              std::max(s.intrinsics_stdev[c][0] / std::abs(in[0]),
                       s.intrinsics_stdev[c][1] / std::abs(in[1])) *
              100;
    }
    rig.focal_stdev_percent.push_back(focal);
  }
  return rig;
}

std::vector<Rigid3> PoseRigFrom(const JointRig& rig, int posed, const Rigid3& cam_from_ground) {
  const auto& models = rig.solution.models;
  if (posed < 0 || static_cast<size_t>(posed) >= models.size())
    throw InputError("camera", "index " + std::to_string(posed) + " is not in the rig");
  const Rigid3 ref_from_ground =
      models[static_cast<size_t>(posed)].cam_from_ground().Inverse() * cam_from_ground;
  std::vector<Rigid3> out;
  out.reserve(models.size());
  for (const auto& m : models) out.push_back(m.cam_from_ground() * ref_from_ground);
  return out;
}

std::vector<Rigid3> PoseRigFromFloorView(const JointRig& rig, int posed, const BoardSpec& board,
                                         const BoardView& floor_view,
                                         const Rigid3& ground_from_board,
                                         const std::string& camera) {
  const auto& models = rig.solution.models;
  if (posed < 0 || static_cast<size_t>(posed) >= models.size())
    throw InputError("camera", "index " + std::to_string(posed) + " is not in the rig");
  CameraModel model = models[static_cast<size_t>(posed)];
  model.set_cam_from_ground({});
  const GroundResult g = SolveGroundPose(model, board, floor_view, ground_from_board, camera);
  return PoseRigFrom(rig, posed, g.cam_from_ground);
}

double TranslationMm(const Rigid3& x, const Rigid3& y) {
  return (x.Inverse().translation - y.Inverse().translation).norm() * 1000;
}

double RotationDeg(const Rigid3& x, const Rigid3& y) {
  return Eigen::AngleAxisd(x.rotation * y.rotation.transpose()).angle() * 180 / M_PI;
}

PairDisagreement CompareRelativePose(const Rigid3& b_from_a_joint, const Rigid3& a_from_ground,
                                     const Rigid3& b_from_ground) {
  PairDisagreement d;
  const Rigid3 one_by_one = b_from_ground * a_from_ground.Inverse();
  d.translation_mm = TranslationMm(b_from_a_joint, one_by_one);
  d.rotation_deg = RotationDeg(b_from_a_joint, one_by_one);
  // Where each optical axis meets the floor (a's ground); the middle of the two. A camera looking
  // above the horizon: the floor below its centre, 1 m ahead.
  auto axis_on_floor = [](const Rigid3& cam_from_ground) {
    const Rigid3 g = cam_from_ground.Inverse();
    const Eigen::Vector3d origin = g.translation, dir = g.rotation.col(2);
    if (dir.z() < -1e-6) return Eigen::Vector3d(origin - dir * (origin.z() / dir.z()));
    Eigen::Vector3d ahead = origin + Eigen::Vector3d(dir.x(), dir.y(), 0).normalized();
    ahead.z() = 0;
    return ahead;
  };
  d.floor_point = 0.5 * (axis_on_floor(a_from_ground) + axis_on_floor(b_from_ground));
  // In b: by its own ground pose, and by a's ground pose carried through the joint solve.
  const Eigen::Vector3d own = b_from_ground * d.floor_point;
  const Eigen::Vector3d joint = b_from_a_joint * (a_from_ground * d.floor_point);
  d.floor_point_mm = (own - joint).norm() * 1000;
  return d;
}

}  // namespace ss::calib
