#include "calib/workflow.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <optional>
#include <sstream>

#include "calib/mrcal_corners.h"
#include "core/error.h"
#include "core/log.h"
#include "core/replace_file.h"

namespace ss::calib {

namespace fs = std::filesystem;

namespace {

void WriteJson(const std::string& path, const nlohmann::json& j) {
  ReplaceFile(path, j.dump(2) + "\n", "the report");
}

void MakeDir(const std::string& dir) {
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec) throw WorkError(dir, "cannot create the output folder: " + ec.message());
}

nlohmann::json PoseJson(const Rigid3& t) {
  double rt[6];
  t.ToRt(rt);
  return nlohmann::json(std::vector<double>(rt, rt + 6));
}

}  // namespace

JobOutcome RunIntrinsics(const std::vector<CameraViews>& cameras, const IntrinsicsJob& job) {
  MakeDir(job.out_dir);
  JobOutcome out;
  std::vector<CameraReport> reports(cameras.size());
  std::vector<int> solve_index(cameras.size(), -1);
  std::vector<SolveCamera> solve_cameras;
  std::vector<BoardObservation> observations;
  constexpr int kMinToSolve = 3;
  for (size_t c = 0; c < cameras.size(); ++c) {
    const auto& cam = cameras[c];
    int accepted = 0;
    for (const auto& v : cam.views) accepted += v.accepted ? 1 : 0;
    out.any_board = out.any_board || accepted > 0;
    if (accepted < kMinToSolve) {
      std::string reason;
      if (accepted == 0) {
        reason = "no board (" + job.board.ToString() + ") found in any of the " +
                 std::to_string(cam.views.size()) + " views";
        if (!cam.views.empty()) reason += " (first view: " + cam.views.front().rejection + ")";
        reason += "; check the board spec";
      } else {
        reason = "too few views: " + std::to_string(accepted) + " accepted (need " +
                 std::to_string(job.verdict.min_views) + "); capture more board views";
      }
      reports[c] = FailedCameraReport(cam.name, cam.views, reason);
      continue;
    }
    solve_index[c] = static_cast<int>(solve_cameras.size());
    solve_cameras.push_back({cam.name, cam.width, cam.height});
    for (size_t i = 0; i < cam.views.size(); ++i) {
      const auto& v = cam.views[i];
      if (v.accepted)
        observations.push_back({solve_index[c], cam.frames[i], v.source, v.ids, v.pixels});
    }
  }
  std::optional<SolveSummary> solution;
  std::string solve_error;
  if (!solve_cameras.empty()) {
    try {
      solution = SolveBoards(job.board, solve_cameras, observations, job.solve);
    } catch (const InputError& e) {
      solve_error = e.what();
    } catch (const WorkError& e) {
      solve_error = e.what();
    }
  }
  out.all_good = true;
  for (size_t c = 0; c < cameras.size(); ++c) {
    const int s = solve_index[c];
    if (s >= 0 && !solution)
      reports[c] = FailedCameraReport(cameras[c].name, cameras[c].views, solve_error);
    if (s >= 0 && solution) {
      CameraReport& r = reports[c];
      r = MakeCameraReport(job.board, *solution, s, cameras[c].views, job.verdict);
      r.camera = cameras[c].name;
      const std::string base = (fs::path(job.out_dir) / cameras[c].name).string();
      r.residual_png = base + ".residuals.png";
      r.coverage_png = base + ".coverage.png";
      WriteResidualPlot(r.residual_png, *solution, s);
      WriteCoverageMap(r.coverage_png, *solution, s, job.verdict);
      if (r.good || job.write_rejected) {
        r.model_file = base + ".cameramodel";
        solution->models[s].Write(r.model_file);
      }
    }
    out.all_good = out.all_good && reports[c].good;
  }
  nlohmann::json j;
  j["board"] = job.board.ToString();
  j["lensmodel"] = job.solve.lensmodel;
  j["reference"] = solve_cameras.empty() ? "" : solve_cameras.front().name;
  j["verdict"] = out.all_good ? "good" : "rejected";
  if (solution) {
    j["summary"] = solution->summary;
    j["pixel_sigma"] = solution->pixel_sigma;
    j["board_warp_m"] = {solution->board_warp[0], solution->board_warp[1]};
    // cam_from_ref as mrcal rt, reference = the first solved camera
    j["poses"] = nlohmann::json::object();
    for (size_t c = 0; c < cameras.size(); ++c) {
      if (solve_index[c] >= 0)
        j["poses"][cameras[c].name] = PoseJson(solution->models[solve_index[c]].cam_from_ground());
    }
  }
  if (!solve_error.empty()) j["error"] = solve_error;
  // The accepted corners as mrcal-calibrate-cameras reads them, and the command that solves them.
  if (out.any_board) {
    const std::string vnl = (fs::path(job.out_dir) / "corners.vnl").string();
    {
      std::ofstream f(vnl);
      f << MrcalCornersVnl(job.board, cameras);
      if (!f) throw WorkError(vnl, "cannot write the corners");
    }
    double focal = cameras.empty() ? 0 : 0.8 * cameras.front().width;
    if (solution) focal = solution->models.front().intrinsics()[0];
    j["mrcal_cross_check"] = {
        {"corners", vnl},
        {"command",
         MrcalCalibrateCommand(job.board, cameras, vnl, (fs::path(job.out_dir) / "mrcal").string(),
                               job.solve.lensmodel, std::round(focal))}};
  }
  j["cameras"] = nlohmann::json::array();
  std::ostringstream text;
  for (const auto& r : reports) {
    j["cameras"].push_back(ToJson(r));
    text << ToText(r);
  }
  if (!solve_error.empty()) text << "solve failed: " << solve_error << "\n";
  WriteJson((fs::path(job.out_dir) / "intrinsics.json").string(), j);
  out.report = j;
  out.text = text.str();
  return out;
}

JobOutcome RunGround(const std::vector<CameraViews>& cameras,
                     const std::vector<CameraModel>& models, const GroundJob& job) {
  if (models.size() != cameras.size())
    throw InputError("--models", "one camera model per camera is needed");
  MakeDir(job.out_dir);
  JobOutcome out;
  out.all_good = true;
  nlohmann::json j;
  j["board"] = job.board.ToString();
  j["ground_from_board"] = PoseJson(job.ground_from_board);
  j["cameras"] = nlohmann::json::array();
  std::vector<std::optional<GroundResult>> results(cameras.size());
  std::vector<BoardView> used(cameras.size());
  std::vector<std::string> errors(cameras.size());
  for (size_t c = 0; c < cameras.size(); ++c) {
    std::vector<BoardView> still;
    for (const auto& v : cameras[c].views) {
      if (v.accepted && static_cast<int>(still.size()) < job.still_views) still.push_back(v);
    }
    if (still.empty()) {
      errors[c] = "no floor board seen";
      if (!cameras[c].views.empty())
        errors[c] += " (first view: " + cameras[c].views.front().rejection + ")";
      continue;
    }
    out.any_board = true;
    if (models[c].width() != cameras[c].width || models[c].height() != cameras[c].height) {
      errors[c] = "the model's imager is " + std::to_string(models[c].width()) + "x" +
                  std::to_string(models[c].height()) + " but the views are " +
                  std::to_string(cameras[c].width) + "x" + std::to_string(cameras[c].height);
      continue;
    }
    try {
      used[c] = AverageStillViews(still);
    } catch (const InputError& e) {
      Log("calib.ground")->warn("{}; using one view only", e.what());
      used[c] = still.front();
    }
    try {
      results[c] =
          SolveGroundPose(models[c], job.board, used[c], job.ground_from_board, cameras[c].name);
    } catch (const std::runtime_error& e) {
      errors[c] = e.what();
    }
  }
  // A rigid rig: cameras without a floor view follow a camera that has one.
  std::vector<bool> derived(cameras.size(), false);
  if (job.rigid) {
    for (size_t c = 0; c < cameras.size(); ++c) {
      if (results[c]) continue;
      for (size_t k = 0; k < cameras.size(); ++k) {
        if (!results[k] || derived[k]) continue;
        GroundResult g;
        g.camera = cameras[c].name;
        g.cam_from_ground = models[c].cam_from_ground() * models[k].cam_from_ground().Inverse() *
                            results[k]->cam_from_ground;
        g.centre_in_ground = g.cam_from_ground.Inverse().translation;
        g.height_m = g.centre_in_ground.z();
        const Eigen::Vector3d axis =
            g.cam_from_ground.rotation.transpose() * Eigen::Vector3d::UnitZ();
        g.optical_axis_down_deg = std::asin(std::clamp(-axis.z(), -1.0, 1.0)) * 180 / M_PI;
        g.rms_px = g.worst_px = NAN;
        results[c] = g;
        derived[c] = true;
        errors[c] = "";
        break;
      }
    }
  }
  std::ostringstream text;
  char buf[300];
  for (size_t c = 0; c < cameras.size(); ++c) {
    nlohmann::json cj;
    cj["camera"] = cameras[c].name;
    if (!results[c]) {
      cj["error"] = errors[c];
      out.all_good = false;
      text << cameras[c].name << ": FAILED: " << errors[c] << "\n";
      j["cameras"].push_back(cj);
      continue;
    }
    const GroundResult& g = *results[c];
    CameraModel posed = models[c];
    posed.set_cam_from_ground(g.cam_from_ground);
    const std::string file = (fs::path(job.out_dir) / (cameras[c].name + ".cameramodel")).string();
    posed.Write(file);
    auto num = [](double v) {
      return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr);
    };
    cj["model"] = file;
    cj["cam_from_ground_rt"] = PoseJson(g.cam_from_ground);
    cj["centre_in_ground_m"] = {g.centre_in_ground.x(), g.centre_in_ground.y(),
                                g.centre_in_ground.z()};
    cj["height_m"] = g.height_m;
    cj["optical_axis_down_deg"] = g.optical_axis_down_deg;
    cj["board_rms_px"] = num(g.rms_px);
    cj["board_worst_px"] = num(g.worst_px);
    cj["corners"] = g.corners;
    cj["from"] = derived[c] ? "rigid rig (no floor view)" : used[c].source;
    j["cameras"].push_back(cj);
    std::snprintf(buf, sizeof buf,
                  "%s: height %.4f m, at (%.4f, %.4f) m, looking %.1f deg down; floor board RMS "
                  "%.3f px, worst %.3f px "
                  "(%d corners)%s\n",
                  cameras[c].name.c_str(), g.height_m, g.centre_in_ground.x(),
                  g.centre_in_ground.y(), g.optical_axis_down_deg, g.rms_px, g.worst_px, g.corners,
                  derived[c] ? " [from the rigid rig]" : "");
    text << buf;
  }
  j["cross_checks"] = nlohmann::json::array();
  for (size_t a = 0; a < cameras.size(); ++a) {
    for (size_t b = 0; b < cameras.size(); ++b) {
      if (a == b || !results[a] || !results[b] || derived[a] || derived[b]) continue;
      CameraModel ma = models[a], mb = models[b];
      ma.set_cam_from_ground(results[a]->cam_from_ground);
      mb.set_cam_from_ground(results[b]->cam_from_ground);
      const CrossCheck x = CrossReprojection(ma, used[a], mb, used[b], job.ground_from_board);
      if (x.points == 0) continue;
      j["cross_checks"].push_back({{"from", cameras[a].name},
                                   {"to", cameras[b].name},
                                   {"points", x.points},
                                   {"rms_px", x.rms_px},
                                   {"worst_px", x.worst_px}});
      std::snprintf(
          buf, sizeof buf, "  floor points %s -> %s: RMS %.3f px, worst %.3f px (%d points)\n",
          cameras[a].name.c_str(), cameras[b].name.c_str(), x.rms_px, x.worst_px, x.points);
      text << buf;
    }
  }
  j["verdict"] = out.all_good ? "good" : "failed";
  WriteJson((fs::path(job.out_dir) / "ground.json").string(), j);
  out.report = j;
  out.text = text.str();
  return out;
}

}  // namespace ss::calib
