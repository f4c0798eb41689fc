#include "calib/solve.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <set>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <opencv2/calib3d.hpp>

// libmrcal's headers are plain C without extern "C" guards.
extern "C" {
#include <mrcal/mrcal.h>
}

#include "core/error.h"
#include "core/log.h"
#include "core/option_checks.h"

namespace ss::calib {
namespace {

mrcal_pose_t ToPose(const Rigid3& t) {
  double rt[6];
  t.ToRt(rt);
  mrcal_pose_t p;
  for (int i = 0; i < 3; ++i) p.r.xyz[i] = rt[i], p.t.xyz[i] = rt[3 + i];
  return p;
}

Rigid3 FromPose(const mrcal_pose_t& p) {
  const double rt[6] = {p.r.x, p.r.y, p.r.z, p.t.x, p.t.y, p.t.z};
  return Rigid3::FromRt(rt);
}

// mrcal's board frame has its origin on corner 0; ours one square before it.
Rigid3 MrcalFromOurBoard(double square) {
  return {Eigen::Matrix3d::Identity(), Eigen::Vector3d(-square, -square, 0)};
}

// The whole mrcal problem: the arrays mrcal_optimize and its callback take.
struct Problem {
  mrcal_lensmodel_t lens{};
  int nparams = 0, ncam = 0, nframes = 0, w = 0, h = 0;
  double spacing = 0;
  bool warp_on = true;
  std::vector<mrcal_observation_board_t> obs;
  std::vector<mrcal_point3_t> pool;
  std::vector<int> imagersizes;
  std::vector<double> intrinsics;
  std::vector<mrcal_pose_t> extrinsics, frames;
  mrcal_calobject_warp_t warp{};
  mrcal_problem_constants_t constants{-1.0, -1.0};

  mrcal_problem_selections_t Selections(bool distortions, bool outliers, bool warp) const {
    mrcal_problem_selections_t s{};
    s.do_optimize_intrinsics_core = true;
    s.do_optimize_intrinsics_distortions = distortions;
    s.do_optimize_extrinsics = ncam > 1;
    s.do_optimize_frames = true;
    s.do_optimize_calobject_warp = warp;
    s.do_apply_regularization = true;
    s.do_apply_outlier_rejection = outliers;
    return s;
  }
  int Nobs() const { return static_cast<int>(obs.size()); }
  int Nmeasurements(mrcal_problem_selections_t s) const {
    return mrcal_num_measurements(Nobs(), 0, w, h, ncam, ncam - 1, nframes, 0, 0, s, &lens);
  }
  int Nstate(mrcal_problem_selections_t s) const {
    return mrcal_num_states(ncam, ncam - 1, nframes, 0, 0, Nobs(), s, &lens);
  }
  mrcal_stats_t Optimize(mrcal_problem_selections_t s, std::vector<double>* x) {
    x->assign(Nmeasurements(s), 0.0);
    return mrcal_optimize(nullptr, -1, x->data(), static_cast<int>(x->size() * sizeof(double)),
                          intrinsics.data(), extrinsics.empty() ? nullptr : extrinsics.data(),
                          frames.data(), nullptr, &warp, ncam, ncam - 1, nframes, 0, 0, obs.data(),
                          nullptr, Nobs(), 0, pool.data(), &lens, imagersizes.data(), s, &constants,
                          spacing, w, h, false, false);
  }
  // mrcal's residual vector at the current state.
  bool Residuals(mrcal_problem_selections_t s, std::vector<double>* x) const {
    std::vector<double> b(Nstate(s));
    x->assign(Nmeasurements(s), 0.0);
    return mrcal_optimizer_callback(
        b.data(), static_cast<int>(b.size() * sizeof(double)), x->data(),
        static_cast<int>(x->size() * sizeof(double)), nullptr, intrinsics.data(),
        extrinsics.empty() ? nullptr : extrinsics.data(), frames.data(), nullptr, &warp, ncam,
        ncam - 1, nframes, 0, 0, obs.data(), nullptr, Nobs(), 0, pool.data(), &lens,
        imagersizes.data(), s, &constants, spacing, w, h, false);
  }
  // Our state layout: intrinsics, extrinsics (rt), frames (rt), warp.
  std::vector<double> State() const {
    std::vector<double> v(intrinsics);
    for (const auto* poses : {&extrinsics, &frames}) {
      for (const auto& p : *poses) v.insert(v.end(), {p.r.x, p.r.y, p.r.z, p.t.x, p.t.y, p.t.z});
    }
    if (warp_on) v.insert(v.end(), {warp.x2, warp.y2});
    return v;
  }
  void SetState(const std::vector<double>& v) {
    size_t k = 0;
    for (double& d : intrinsics) d = v[k++];
    for (auto* poses : {&extrinsics, &frames}) {
      for (auto& p : *poses) {
        for (int i = 0; i < 3; ++i) p.r.xyz[i] = v[k++];
        for (int i = 0; i < 3; ++i) p.t.xyz[i] = v[k++];
      }
    }
    if (warp_on) warp.x2 = v[k++], warp.y2 = v[k++];
  }
};

// A finite-difference step suited to each state variable.
std::vector<double> Steps(const Problem& p) {
  std::vector<double> steps;
  for (int c = 0; c < p.ncam; ++c) {
    for (int i = 0; i < p.nparams; ++i) steps.push_back(i < 4 ? 1e-4 : 1e-7);
  }
  steps.resize(steps.size() + 6 * (p.extrinsics.size() + p.frames.size()), 1e-7);
  if (p.warp_on) steps.insert(steps.end(), {1e-7, 1e-7});
  return steps;
}

struct Seed {
  Eigen::Matrix3d k = Eigen::Matrix3d::Identity();
};

std::vector<cv::Point3f> ObjectPoints(const BoardSpec& board, const BoardObservation& o) {
  std::vector<cv::Point3f> pts;
  for (int id : o.ids) {
    const Eigen::Vector3d p = board.Corner(id);
    pts.emplace_back(static_cast<float>(p.x()), static_cast<float>(p.y()), 0.f);
  }
  return pts;
}

std::vector<cv::Point2f> ImagePoints(const BoardObservation& o) {
  std::vector<cv::Point2f> pts;
  for (const auto& q : o.pixels)
    pts.emplace_back(static_cast<float>(q.x()), static_cast<float>(q.y()));
  return pts;
}

}  // namespace

bool SolveOptions::IsValid(std::string* why) const {
  OptionProblems check(why);
  mrcal_lensmodel_t lens{};
  const bool known = mrcal_lensmodel_from_name(&lens, lensmodel.c_str());
  check(known, "lensmodel",
        "unknown mrcal lens model \"" + lensmodel + "\" (e.g. LENSMODEL_OPENCV8)");
  check(!known || mrcal_lensmodel_metadata(&lens).has_core, "lensmodel",
        lensmodel + " has no fx fy cx cy core; pick another model");
  return check.ok();
}

SolveSummary SolveBoards(const BoardSpec& board, const std::vector<SolveCamera>& cameras,
                         const std::vector<BoardObservation>& observations,
                         const SolveOptions& options) {
  if (std::string why; !options.IsValid(&why)) throw InputError("calibration solve options", why);
  auto log = Log("calib.solve");
  Problem p;
  mrcal_lensmodel_from_name(&p.lens, options.lensmodel.c_str());  // known: IsValid
  p.nparams = mrcal_lensmodel_num_params(&p.lens);
  p.ncam = static_cast<int>(cameras.size());
  p.w = board.corners_x();
  p.h = board.corners_y();
  p.spacing = board.square_m;
  p.warp_on = options.optimize_board_warp;
  if (p.ncam == 0) throw InputError("cameras", "no camera to calibrate");

  // Which frames are used; each camera needs observations.
  std::map<int, int> frame_index;  // frame -> dense index
  std::vector<int> per_camera(p.ncam, 0);
  for (const auto& o : observations) {
    if (o.camera < 0 || o.camera >= p.ncam)
      throw InputError(o.source, "observation of an unknown camera");
    if (o.ids.size() != o.pixels.size() || o.ids.size() < 4) {
      throw InputError(o.source, "an observation needs at least 4 corners");
    }
    frame_index.emplace(o.frame, 0);
    ++per_camera[o.camera];
  }
  for (int c = 0; c < p.ncam; ++c) {
    if (per_camera[c] == 0) throw InputError(cameras[c].name, "no accepted view of the board");
  }
  int next = 0;
  for (auto& [frame, index] : frame_index) index = next++;
  p.nframes = next;

  // Seed the intrinsics (pinhole guess) and every observation's pose.
  std::vector<Eigen::Matrix3d> k(p.ncam);
  for (int c = 0; c < p.ncam; ++c) {
    std::vector<std::vector<cv::Point3f>> object;
    std::vector<std::vector<cv::Point2f>> image;
    for (const auto& o : observations) {
      if (o.camera == c) object.push_back(ObjectPoints(board, o)), image.push_back(ImagePoints(o));
    }
    const cv::Size size(cameras[c].width, cameras[c].height);
    double f = 0.8 * size.width;
    try {
      const cv::Mat k0 = cv::initCameraMatrix2D(object, image, size, 1.0);
      const double guess = 0.5 * (k0.at<double>(0, 0) + k0.at<double>(1, 1));
      if (std::isfinite(guess) && guess > 0.1 * size.width && guess < 20.0 * size.width) f = guess;
    } catch (const cv::Exception&) {
    }
    k[c] << f, 0, (size.width - 1) / 2.0, 0, f, (size.height - 1) / 2.0, 0, 0, 1;
    std::vector<double> in(p.nparams, 0.0);
    in[0] = in[1] = f;
    in[2] = (size.width - 1) / 2.0;
    in[3] = (size.height - 1) / 2.0;
    p.intrinsics.insert(p.intrinsics.end(), in.begin(), in.end());
    p.imagersizes.insert(p.imagersizes.end(), {size.width, size.height});
  }
  std::vector<Rigid3> cam_from_board(observations.size());
  for (size_t i = 0; i < observations.size(); ++i) {
    const auto& o = observations[i];
    cv::Mat kk(3, 3, CV_64F);
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) kk.at<double>(r, c) = k[o.camera](r, c);
    cv::Mat rvec, tvec;
    if (!cv::solvePnP(ObjectPoints(board, o), ImagePoints(o), kk, cv::noArray(), rvec, tvec, false,
                      cv::SOLVEPNP_IPPE)) {
      throw WorkError(o.source, "no initial board pose (solvePnP failed)");
    }
    const double rt[6] = {rvec.at<double>(0), rvec.at<double>(1), rvec.at<double>(2),
                          tvec.at<double>(0), tvec.at<double>(1), tvec.at<double>(2)};
    cam_from_board[i] = Rigid3::FromRt(rt);
  }
  // Chain the cameras to camera 0 through shared frames.
  std::vector<bool> cam_known(p.ncam, false);
  std::vector<Rigid3> cam_from_ref(p.ncam);
  std::vector<bool> frame_known(p.nframes, false);
  std::vector<Rigid3> ref_from_board(p.nframes);
  cam_known[0] = true;
  for (bool progress = true; progress;) {
    progress = false;
    for (size_t i = 0; i < observations.size(); ++i) {
      const int c = observations[i].camera, f = frame_index[observations[i].frame];
      if (cam_known[c] && !frame_known[f]) {
        ref_from_board[f] = cam_from_ref[c].Inverse() * cam_from_board[i];
        frame_known[f] = progress = true;
      } else if (!cam_known[c] && frame_known[f]) {
        cam_from_ref[c] = cam_from_board[i] * ref_from_board[f].Inverse();
        cam_known[c] = progress = true;
      }
    }
  }
  for (int c = 0; c < p.ncam; ++c) {
    if (!cam_known[c]) {
      throw InputError(cameras[c].name,
                       "shares no board view with " + cameras[0].name +
                           " (directly or through other cameras): its pose cannot be joined");
    }
    if (c > 0) p.extrinsics.push_back(ToPose(cam_from_ref[c]));
  }
  const Rigid3 board_from_mrcal = MrcalFromOurBoard(board.square_m).Inverse();
  for (int f = 0; f < p.nframes; ++f)
    p.frames.push_back(ToPose(ref_from_board[f] * board_from_mrcal));

  // The observation pool: every corner of the grid, missing ones weighted -1.
  const int grid = p.w * p.h;
  p.pool.assign(observations.size() * grid, mrcal_point3_t{{0, 0, -1}});
  for (size_t i = 0; i < observations.size(); ++i) {
    const auto& o = observations[i];
    mrcal_observation_board_t ob{};
    ob.icam.intrinsics = o.camera;
    ob.icam.extrinsics = o.camera - 1;
    ob.iframe = frame_index[o.frame];
    p.obs.push_back(ob);
    for (size_t j = 0; j < o.ids.size(); ++j) {
      if (o.ids[j] < 0 || o.ids[j] >= grid)
        throw InputError(o.source, "corner id outside the board");
      p.pool[i * grid + o.ids[j]] = mrcal_point3_t{{o.pixels[j].x(), o.pixels[j].y(), 1.0}};
    }
  }
  std::vector<bool> present(p.pool.size());
  for (size_t k2 = 0; k2 < p.pool.size(); ++k2) present[k2] = p.pool[k2].z >= 0;

  // Stage 1: core and poses, no distortion. Then everything, with outlier rejection.
  const auto progress = [&](const char* stage, double fraction) {
    if (options.progress) options.progress(stage, fraction);
  };
  progress("stage 1 of 3: the lens core and the board poses", 0.1);
  std::vector<double> x;
  mrcal_stats_t stats = p.Optimize(p.Selections(false, false, false), &x);
  log->debug("stage 1 (core only): RMS {:.3f} px", stats.rms_reproj_error__pixels);
  // As mrcal-calibrate-cameras: everything but the board warp first (outliers
  // found here stay out), then the warp too. Same corners, same outlier set.
  if (p.warp_on) {
    progress("stage 2 of 3: distortion, outliers rejected", 0.3);
    stats = p.Optimize(p.Selections(true, options.reject_outliers, false), &x);
    log->debug("stage 2 (no board warp): RMS {:.3f} px, {} outliers",
               stats.rms_reproj_error__pixels, stats.Noutliers);
  }
  const auto final_sel = p.Selections(true, options.reject_outliers, p.warp_on);
  progress("stage 3 of 3: everything, the board's flex too", 0.55);
  stats = p.Optimize(final_sel, &x);
  if (!std::isfinite(stats.rms_reproj_error__pixels) || stats.rms_reproj_error__pixels < 0) {
    throw WorkError("mrcal_optimize", "the solve failed (no finite RMS)");
  }

  SolveSummary out;
  out.mrcal_rms_px = stats.rms_reproj_error__pixels;
  out.intrinsics_count = p.nparams;
  out.board_warp[0] = p.warp.x2;
  out.board_warp[1] = p.warp.y2;
  char name[256];
  if (!mrcal_lensmodel_name(name, sizeof name, &p.lens))
    throw WorkError("mrcal", "cannot name the lens model");
  for (int c = 0; c < p.ncam; ++c) {
    const std::vector<double> in(p.intrinsics.begin() + c * p.nparams,
                                 p.intrinsics.begin() + (c + 1) * p.nparams);
    const Rigid3 pose = c == 0 ? Rigid3{} : FromPose(p.extrinsics[c - 1]);
    out.models.emplace_back(name, in, cameras[c].width, cameras[c].height, pose);
  }
  for (int f = 0; f < p.nframes; ++f)
    out.ref_from_board.push_back(FromPose(p.frames[f]) * MrcalFromOurBoard(board.square_m));
  out.frame_used.assign(p.nframes, true);
  for (const auto& ob : p.obs) out.observation_frame.push_back(ob.iframe);

  // Residuals per corner, from mrcal's measurement vector.
  std::vector<double> sum2(p.ncam, 0.0), worst(p.ncam, 0.0);
  std::vector<int> inliers(p.ncam, 0);
  out.outliers.assign(p.ncam, 0);
  for (int i = 0; i < p.Nobs(); ++i) {
    const int c = observations[i].camera;
    const int base = mrcal_measurement_index_boards(i, p.Nobs(), 0, p.w, p.h);
    for (int id = 0; id < grid; ++id) {
      const size_t k2 = static_cast<size_t>(i) * grid + id;
      if (!present[k2]) continue;
      CornerResidual r;
      r.camera = c;
      r.observation = i;
      r.id = id;
      r.observed = {p.pool[k2].x, p.pool[k2].y};
      r.residual = {x[base + 2 * id], x[base + 2 * id + 1]};
      r.outlier = p.pool[k2].z < 0;
      if (r.outlier) {
        ++out.outliers[c];
      } else {
        sum2[c] += r.residual.squaredNorm();
        worst[c] = std::max(worst[c], r.residual.norm());
        ++inliers[c];
      }
      out.corners.push_back(r);
    }
  }
  double all2 = 0;
  int all_n = 0;
  for (int c = 0; c < p.ncam; ++c) {
    out.rms_px.push_back(inliers[c] ? std::sqrt(sum2[c] / inliers[c]) : NAN);
    out.worst_px.push_back(worst[c]);
    all2 += sum2[c];
    all_n += inliers[c];
  }
  out.pixel_sigma = all_n ? std::sqrt(all2 / (2.0 * all_n)) : NAN;
  out.state = p.State();

  // Covariance: sigma^2 (J^T J)^-1 with J = d(mrcal residuals)/d(state), central differences.
  out.intrinsics_stdev.assign(p.ncam, std::vector<double>(p.nparams, NAN));
  if (options.compute_covariance) {
    progress("the covariance: how well each parameter is known", 0.8);
    const std::vector<double> steps = Steps(p);
    const std::vector<double> s0 = out.state;
    const int nstate = static_cast<int>(s0.size());
    std::vector<double> xp, xm;
    Eigen::MatrixXd jac;
    bool ok = true;
    for (int j = 0; j < nstate && ok; ++j) {
      std::vector<double> s = s0;
      s[j] = s0[j] + steps[j];
      p.SetState(s);
      ok = p.Residuals(final_sel, &xp);
      s[j] = s0[j] - steps[j];
      p.SetState(s);
      ok = ok && p.Residuals(final_sel, &xm);
      if (j == 0) jac.setZero(static_cast<int>(xp.size()), nstate);
      for (size_t m = 0; m < xp.size(); ++m)
        jac(static_cast<int>(m), j) = (xp[m] - xm[m]) / (2 * steps[j]);
    }
    p.SetState(s0);
    if (ok) {
      const Eigen::MatrixXd jtj = jac.transpose() * jac;
      const Eigen::LDLT<Eigen::MatrixXd> ldlt(jtj);
      if (ldlt.info() == Eigen::Success) {
        out.covariance = ldlt.solve(Eigen::MatrixXd::Identity(nstate, nstate)) *
                         (out.pixel_sigma * out.pixel_sigma);
        for (int c = 0; c < p.ncam; ++c) {
          for (int i = 0; i < p.nparams; ++i) {
            const int idx = c * p.nparams + i;
            out.intrinsics_stdev[c][i] = std::sqrt(std::max(0.0, out.covariance(idx, idx)));
          }
        }
      }
    }
    if (out.covariance.size() == 0)
      log->warn("no covariance: the problem is singular or mrcal's callback failed");
  }
  char line[512];  // the model name alone may take 255
  std::snprintf(line, sizeof line, "%d camera(s), %d views, %s: RMS %.3f px, %d outlier corners",
                p.ncam, p.Nobs(), name, all_n ? std::sqrt(all2 / all_n) : NAN, stats.Noutliers);
  out.summary = line;
  log->info("{}", out.summary);
  return out;
}

double ProjectionStdev(const SolveSummary& solution, const BoardSpec& board, int camera,
                       const Eigen::Vector2d& pixel, double distance_m) {
  if (solution.covariance.size() == 0 || camera < 0 ||
      camera >= static_cast<int>(solution.models.size()))
    return NAN;
  const CameraModel& model = solution.models[camera];
  mrcal_lensmodel_t lens{};
  if (!mrcal_lensmodel_from_name(&lens, model.lensmodel().c_str())) return NAN;
  const int np = solution.intrinsics_count, ncam = static_cast<int>(solution.models.size());
  const int nframes = static_cast<int>(solution.ref_from_board.size());
  const int ext0 = ncam * np, frame0 = ext0 + 6 * (ncam - 1);
  const auto& s0 = solution.state;
  auto pose_at = [](const std::vector<double>& s, int at) { return Rigid3::FromRt(&s[at]); };
  // The point in camera coordinates, then in every board frame (held fixed).
  const Eigen::Vector3d ray = model.Unproject(pixel);
  if (!ray.allFinite()) return NAN;
  const Eigen::Vector3d p_cam = ray.normalized() * distance_m;
  const Rigid3 cam_from_ref = camera == 0 ? Rigid3{} : pose_at(s0, ext0 + 6 * (camera - 1));
  const Eigen::Vector3d p_ref = cam_from_ref.Inverse() * p_cam;
  std::vector<Eigen::Vector3d> p_frame;
  p_frame.reserve(nframes);
  for (int f = 0; f < nframes; ++f)
    p_frame.push_back(pose_at(s0, frame0 + 6 * f).Inverse() * p_ref);
  // q(state): mean over frames of the point carried back to the reference, then projected.
  auto project = [&](const std::vector<double>& s) {
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();
    for (int f = 0; f < nframes; ++f) mean += pose_at(s, frame0 + 6 * f) * p_frame[f];
    mean /= nframes;
    const Rigid3 e = camera == 0 ? Rigid3{} : pose_at(s, ext0 + 6 * (camera - 1));
    const Eigen::Vector3d pc = e * mean;
    mrcal_point3_t in{{pc.x(), pc.y(), pc.z()}};
    mrcal_point2_t q;
    mrcal_project(&q, nullptr, nullptr, &in, 1, &lens, &s[camera * np]);
    return Eigen::Vector2d(q.x, q.y);
  };
  std::vector<int> vars;
  vars.reserve(np + 6);
  for (int i = 0; i < np; ++i) vars.push_back(camera * np + i);
  if (camera > 0)
    for (int i = 0; i < 6; ++i) vars.push_back(ext0 + 6 * (camera - 1) + i);
  for (int i = 0; i < 6 * nframes; ++i) vars.push_back(frame0 + i);
  Eigen::MatrixXd jq(2, vars.size());
  for (size_t j = 0; j < vars.size(); ++j) {
    const double h = vars[j] < ncam * np && (vars[j] - camera * np) < 4 ? 1e-4 : 1e-7;
    std::vector<double> sp = s0, sm = s0;
    sp[vars[j]] += h;
    sm[vars[j]] -= h;
    jq.col(static_cast<int>(j)) = (project(sp) - project(sm)) / (2 * h);
  }
  Eigen::MatrixXd sub(vars.size(), vars.size());
  for (size_t a = 0; a < vars.size(); ++a)
    for (size_t b = 0; b < vars.size(); ++b) sub(a, b) = solution.covariance(vars[a], vars[b]);
  const Eigen::Matrix2d var = jq * sub * jq.transpose();
  const double worst = Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d>(var).eigenvalues().maxCoeff();
  (void)board;
  return std::sqrt(std::max(0.0, worst));
}

}  // namespace ss::calib
