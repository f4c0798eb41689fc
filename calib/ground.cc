#include "calib/ground.h"

#include <algorithm>
#include <cmath>
#include <map>

#include <Eigen/Geometry>
#include <opencv2/calib3d.hpp>

// libmrcal's headers are plain C without extern "C" guards.
extern "C" {
#include <mrcal/mrcal.h>
}

#include "core/error.h"
#include "core/log.h"

namespace ss::calib {

Rigid3 FloorBoardPose(double x_m, double y_m, double yaw_deg, double thickness_m) {
  const Eigen::Matrix3d flip = Eigen::Vector3d(1, -1, -1).asDiagonal();
  const Eigen::Matrix3d yaw =
      Eigen::AngleAxisd(yaw_deg * M_PI / 180, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  return {yaw * flip, Eigen::Vector3d(x_m, y_m, thickness_m)};
}

BoardView AverageStillViews(const std::vector<BoardView>& views, double max_motion_px) {
  std::map<int, std::vector<Eigen::Vector2d>> by_id;
  const BoardView* first = nullptr;
  int used = 0;
  for (const auto& v : views) {
    if (!v.accepted) continue;
    if (!first) first = &v;
    ++used;
    for (size_t i = 0; i < v.ids.size(); ++i) by_id[v.ids[i]].push_back(v.pixels[i]);
  }
  if (!first)
    throw InputError(views.empty() ? "views" : views.front().source,
                     "no accepted view of the board");
  BoardView out = *first;
  out.ids.clear();
  out.pixels.clear();
  out.source = first->source + (used > 1 ? " (mean of " + std::to_string(used) + " views)" : "");
  for (const auto& [id, pts] : by_id) {
    if (static_cast<int>(pts.size()) * 2 < used) continue;  // seen in fewer than half the views
    Eigen::Vector2d mean = Eigen::Vector2d::Zero();
    for (const auto& p : pts) mean += p;
    mean /= static_cast<double>(pts.size());
    for (const auto& p : pts) {
      if ((p - mean).norm() > max_motion_px) {
        throw InputError(first->source,
                         "the board moved between the views averaged for the ground (corner " +
                             std::to_string(id) + " moved " + std::to_string((p - mean).norm()) +
                             " px); keep it still on the floor");
      }
    }
    out.ids.push_back(id);
    out.pixels.push_back(mean);
  }
  return out;
}

GroundResult SolveGroundPose(const CameraModel& model, const BoardSpec& board,
                             const BoardView& view, const Rigid3& ground_from_board,
                             const std::string& camera) {
  if (view.ids.size() < 4 || view.ids.size() != view.pixels.size()) {
    throw InputError(view.source, "the floor board needs at least 4 detected corners");
  }
  // Seed: IPPE on the undistorted rays (normalized image coordinates).
  std::vector<Eigen::Vector3d> rays(view.pixels.size());
  model.UnprojectMany(view.pixels.data(), view.pixels.size(), rays.data());
  std::vector<cv::Point3f> object;
  std::vector<cv::Point2f> normalized;
  for (size_t i = 0; i < rays.size(); ++i) {
    if (!rays[i].allFinite() || rays[i].z() <= 0) continue;
    const Eigen::Vector3d p = board.Corner(view.ids[i]);
    object.emplace_back(static_cast<float>(p.x()), static_cast<float>(p.y()), 0.f);
    normalized.emplace_back(static_cast<float>(rays[i].x() / rays[i].z()),
                            static_cast<float>(rays[i].y() / rays[i].z()));
  }
  if (object.size() < 4)
    throw WorkError(view.source, "the lens model cannot unproject the floor board's corners");
  cv::Mat rvec, tvec;
  const cv::Mat eye = cv::Mat::eye(3, 3, CV_64F);
  if (!cv::solvePnP(object, normalized, eye, cv::noArray(), rvec, tvec, false, cv::SOLVEPNP_IPPE)) {
    throw WorkError(view.source, "no pose for the floor board (solvePnP failed)");
  }
  cv::solvePnPRefineLM(object, normalized, eye, cv::noArray(), rvec, tvec);
  double rt[6] = {rvec.at<double>(0), rvec.at<double>(1), rvec.at<double>(2),
                  tvec.at<double>(0), tvec.at<double>(1), tvec.at<double>(2)};
  Rigid3 cam_from_board = Rigid3::FromRt(rt);

  // Refine in pixels with mrcal: the camera is the reference, the board the one frame.
  mrcal_lensmodel_t lens{};
  if (!mrcal_lensmodel_from_name(&lens, model.lensmodel().c_str())) {
    throw WorkError(model.lensmodel(), "libmrcal does not know this lens model");
  }
  const int w = board.corners_x(), h = board.corners_y();
  std::vector<mrcal_point3_t> pool(w * h, mrcal_point3_t{{0, 0, -1}});
  for (size_t i = 0; i < view.ids.size(); ++i)
    pool[view.ids[i]] = mrcal_point3_t{{view.pixels[i].x(), view.pixels[i].y(), 1}};
  const Rigid3 mrcal_to_ours{Eigen::Matrix3d::Identity(),
                             Eigen::Vector3d(board.square_m, board.square_m, 0)};
  Rigid3 cam_from_mrcal = cam_from_board * mrcal_to_ours;
  double frt[6];
  cam_from_mrcal.ToRt(frt);
  mrcal_pose_t frame{};
  for (int i = 0; i < 3; ++i) frame.r.xyz[i] = frt[i], frame.t.xyz[i] = frt[3 + i];
  std::vector<double> intrinsics = model.intrinsics();
  mrcal_observation_board_t ob{};
  ob.icam.intrinsics = 0;
  ob.icam.extrinsics = -1;
  ob.iframe = 0;
  const int imager[2] = {model.width(), model.height()};
  mrcal_problem_selections_t sel{};
  sel.do_optimize_frames = true;
  mrcal_problem_constants_t constants{-1.0, -1.0};
  mrcal_calobject_warp_t warp{};
  std::vector<double> x(mrcal_num_measurements(1, 0, w, h, 1, 0, 1, 0, 0, sel, &lens));
  const mrcal_stats_t stats = mrcal_optimize(
      nullptr, -1, x.data(), static_cast<int>(x.size() * sizeof(double)), intrinsics.data(),
      nullptr, &frame, nullptr, &warp, 1, 0, 1, 0, 0, &ob, nullptr, 1, 0, pool.data(), &lens,
      imager, sel, &constants, board.square_m, w, h, false, false);
  if (std::isfinite(stats.rms_reproj_error__pixels) && stats.rms_reproj_error__pixels >= 0) {
    const double r2[6] = {frame.r.x, frame.r.y, frame.r.z, frame.t.x, frame.t.y, frame.t.z};
    cam_from_board = Rigid3::FromRt(r2) * mrcal_to_ours.Inverse();
  } else {
    Log("calib.ground")->warn("{}: mrcal refinement failed; keeping the OpenCV pose", view.source);
  }

  GroundResult out;
  out.camera = camera;
  out.cam_from_ground = cam_from_board * ground_from_board.Inverse();
  out.centre_in_ground = out.cam_from_ground.Inverse().translation;
  out.height_m = out.centre_in_ground.z();
  const Eigen::Vector3d axis = out.cam_from_ground.rotation.transpose() * Eigen::Vector3d::UnitZ();
  out.optical_axis_down_deg = std::asin(std::clamp(-axis.z(), -1.0, 1.0)) * 180 / M_PI;
  // Reprojection of the board through the final pose.
  double sum2 = 0;
  CameraModel posed = model;
  posed.set_cam_from_ground(out.cam_from_ground);
  for (size_t i = 0; i < view.ids.size(); ++i) {
    const Eigen::Vector2d q = posed.ProjectGround(ground_from_board * board.Corner(view.ids[i]));
    const double e = (q - view.pixels[i]).norm();
    if (!std::isfinite(e)) continue;
    sum2 += e * e;
    out.worst_px = std::max(out.worst_px, e);
    ++out.corners;
  }
  out.rms_px = out.corners ? std::sqrt(sum2 / out.corners) : NAN;
  return out;
}

CrossCheck CrossReprojection(const CameraModel& a, const BoardView& view_a, const CameraModel& b,
                             const BoardView& view_b, const Rigid3& ground_from_board) {
  CrossCheck out;
  std::map<int, Eigen::Vector2d> in_b;
  for (size_t i = 0; i < view_b.ids.size(); ++i) in_b[view_b.ids[i]] = view_b.pixels[i];
  // The board's surface plane in ground coordinates: n . p = d.
  const Eigen::Vector3d n = ground_from_board.rotation.col(2);
  const double d = n.dot(ground_from_board.translation);
  double sum2 = 0;
  for (size_t i = 0; i < view_a.ids.size(); ++i) {
    const auto it = in_b.find(view_a.ids[i]);
    if (it == in_b.end()) continue;
    const Ray ray = a.RayInGround(view_a.pixels[i]);
    const double denom = n.dot(ray.direction);
    if (!ray.direction.allFinite() || std::abs(denom) < 1e-12) continue;
    const double s = (d - n.dot(ray.origin)) / denom;
    if (s <= 0) continue;
    const Eigen::Vector2d q = b.ProjectGround(ray.origin + s * ray.direction);
    const double e = (q - it->second).norm();
    if (!std::isfinite(e)) continue;
    sum2 += e * e;
    out.worst_px = std::max(out.worst_px, e);
    ++out.points;
  }
  out.rms_px = out.points ? std::sqrt(sum2 / out.points) : NAN;
  return out;
}

}  // namespace ss::calib
