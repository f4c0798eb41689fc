// spritestation calibrate intrinsics|ground|enclosure: camera calibration
// (docs/calibration.md). The work lives in calib/workflow.h; this file parses
// options and prints. Exit 1 when a camera's calibration is not trusted (the
// report says why), 2 for bad input (no board of that spec anywhere, bad files).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>

#include "apps/commands.h"
#include "calib/board.h"
#include "calib/enclosure.h"
#include "calib/inputs.h"
#include "calib/wizard.h"
#include "calib/wizard_run.h"
#include "calib/workflow.h"
#include "capture/camera_source.h"
#include "capture/replay/replay_source.h"
#include "config/station_config.h"
#include "config/station_save.h"
#include "core/camera_model.h"
#include "core/error.h"
#include "core/frame.h"
#include "core/replace_file.h"
#include "core/session.h"

namespace ss::apps {
namespace {

namespace fs = std::filesystem;

struct InputOptions {
  std::vector<std::string> inputs;
  std::string board;
  std::vector<std::string> cameras;
  int every = 0, max_views = 40, first = 0, count = 0;
  double max_edge_width_px = 4.0;
  int min_corners = 12;
};

void AddInputOptions(CLI::App* cmd, InputOptions* o, int default_max_views) {
  o->max_views = default_max_views;
  cmd->add_option("input", o->inputs,
                  "A recorded session folder, or image files / a folder of images")
      ->required();
  cmd->add_option(
         "--board", o->board,
         "Board: chessboard:COLSxROWS:SQUARE_M or charuco:COLSxROWS:SQUARE_M:MARKER_M[:DICT]")
      ->required();
  cmd->add_option("--camera", o->cameras, "Session: only this camera (repeat for several)");
  cmd->add_option("--every", o->every,
                  "Session: use every N-th frame (default: spread --max-views over the session)");
  cmd->add_option("--max-views", o->max_views, "Session: views per camera");
  cmd->add_option("--first", o->first, "Session: first frame to use");
  cmd->add_option("--count", o->count, "Session: frames to use from --first (0: to the end)");
  cmd->add_option("--max-edge-width", o->max_edge_width_px,
                  "Reject views whose square edges rise over more pixels");
  cmd->add_option("--min-corners", o->min_corners, "Reject views with fewer corners");
}

std::vector<calib::CameraViews> LoadViews(const InputOptions& o, const calib::BoardSpec& board) {
  calib::DetectOptions detect;
  detect.max_edge_width_px = o.max_edge_width_px;
  detect.min_corners = o.min_corners;
  if (o.inputs.size() == 1 && calib::IsSessionDir(o.inputs[0])) {
    calib::SampleOptions sample;
    sample.every = o.every;
    sample.max_views = o.max_views;
    sample.first = o.first;
    sample.count = o.count;
    sample.cameras = o.cameras;
    return calib::DetectInSession(o.inputs[0], board, detect, sample);
  }
  return {calib::DetectInImages(o.inputs, board, detect,
                                o.cameras.empty() ? "camera0" : o.cameras.front())};
}

void Print(const calib::JobOutcome& outcome, bool json) {
  if (json) {
    std::printf("%s\n", outcome.report.dump(2).c_str());
  } else {
    std::printf("%s", outcome.text.c_str());
  }
  std::fflush(stdout);
}

void AddIntrinsics(CLI::App& parent) {
  auto* cmd = parent.add_subcommand(
      "intrinsics", "Solve lens intrinsics (mrcal) from board views; several cameras jointly");
  auto in = std::make_shared<InputOptions>();
  // The flags are the job's own fields: its defaults are the solver's and the verdict's.
  auto job = std::make_shared<calib::IntrinsicsJob>();
  auto json = std::make_shared<bool>(false);
  auto keep_outliers = std::make_shared<bool>(false);
  AddInputOptions(cmd, in.get(), 40);
  cmd->add_option("--out", job->out_dir,
                  "Output folder: CAMERA.cameramodel, plots, intrinsics.json")
      ->required();
  cmd->add_option("--lensmodel", job->solve.lensmodel,
                  "mrcal lens model, e.g. LENSMODEL_OPENCV8, "
                  "LENSMODEL_SPLINED_STEREOGRAPHIC_order=3_Nx=16_Ny=12_fov_x_deg=100")
      ->capture_default_str();
  cmd->add_option("--min-views", job->verdict.min_views,
                  "Accepted views needed for a trusted model")
      ->capture_default_str();
  cmd->add_option("--max-rms", job->verdict.max_rms_px,
                  "Largest trusted RMS reprojection error, px")
      ->capture_default_str();
  cmd->add_option("--min-coverage", job->verdict.min_coverage,
                  "Fraction of the image's coverage cells that need corners")
      ->capture_default_str();
  cmd->add_flag("--write-rejected", job->write_rejected,
                "Write models even when the verdict is 'rejected'");
  cmd->add_flag("--no-outlier-rejection", *keep_outliers,
                "Keep every corner (mrcal's outlier rejection off)");
  cmd->add_flag("--json", *json, "Print the report as JSON");
  cmd->callback([=] {
    job->board = calib::ParseBoardSpec(in->board);
    job->solve.reject_outliers = !*keep_outliers;
    const auto views = LoadViews(*in, job->board);
    const calib::JobOutcome outcome = calib::RunIntrinsics(views, *job);
    Print(outcome, *json);
    if (!outcome.any_board) {
      throw InputError(in->inputs.front(),
                       "no board " + job->board.ToString() + " found in any view (wrong --board?)");
    }
    if (!outcome.all_good)
      throw WorkError(job->out_dir, "calibration not trusted (see the reasons above)");
  });
}

void AddGround(CLI::App& parent) {
  auto* cmd = parent.add_subcommand(
      "ground", "Pose every camera against the floor from a board lying flat on it");
  auto in = std::make_shared<InputOptions>();
  auto out = std::make_shared<std::string>();
  auto models = std::make_shared<std::vector<std::string>>();
  auto pose = std::make_shared<std::vector<double>>(std::vector<double>{0, 0, 0});
  auto thickness = std::make_shared<double>(0.0);
  auto still = std::make_shared<int>(5);
  auto rigid = std::make_shared<bool>(false);
  auto json = std::make_shared<bool>(false);
  AddInputOptions(cmd, in.get(), 10);
  cmd->add_option("--out", *out,
                  "Output folder: CAMERA.cameramodel with cam_from_ground, ground.json")
      ->required();
  cmd->add_option("--models", *models,
                  "Intrinsics: a folder with CAMERA.cameramodel, or one file per camera (default: "
                  "the session's)");
  cmd->add_option("--board-pose", *pose,
                  "Board's top-left checkered corner on the floor: X Y YAW_DEG")
      ->expected(3);
  cmd->add_option("--board-thickness", *thickness,
                  "Height of the printed surface above the floor, m");
  cmd->add_option("--still-views", *still, "Accepted views of the still board averaged per camera");
  cmd->add_flag("--rigid", *rigid,
                "Models share one reference (joint solve): cameras without a floor view follow");
  cmd->add_flag("--json", *json, "Print the report as JSON");
  cmd->callback([=] {
    calib::GroundJob job;
    job.board = calib::ParseBoardSpec(in->board);
    job.ground_from_board = calib::FloorBoardPose((*pose)[0], (*pose)[1], (*pose)[2], *thickness);
    job.out_dir = *out;
    job.still_views = *still;
    job.rigid = *rigid;
    const auto views = LoadViews(*in, job.board);
    std::vector<CameraModel> cams;
    for (size_t c = 0; c < views.size(); ++c) {
      std::string path;
      if (models->size() == 1 && fs::is_directory((*models)[0])) {
        path = (fs::path((*models)[0]) / (views[c].name + ".cameramodel")).string();
      } else if (models->size() == views.size()) {
        path = (*models)[c];
      } else if (models->empty()) {
        path = views[c].model_path;
      } else {
        throw InputError("--models", "give a folder, or one model per camera (" +
                                         std::to_string(views.size()) + ")");
      }
      if (path.empty()) throw InputError("--models", "no model for camera " + views[c].name);
      cams.push_back(CameraModel::Read(path));
    }
    const calib::JobOutcome outcome = calib::RunGround(views, cams, job);
    Print(outcome, *json);
    if (!outcome.any_board)
      throw InputError(in->inputs.front(),
                       "no board " + job.board.ToString() + " found on the floor");
    if (!outcome.all_good) throw WorkError(*out, "not every camera could be posed (see above)");
  });
}

void AddEnclosure(CLI::App& parent) {
  auto* cmd = parent.add_subcommand("enclosure", "The usable floor polygon, in ground metres");
  auto points = std::make_shared<std::string>();
  auto pixels = std::make_shared<std::string>();
  auto green = std::make_shared<std::string>();
  auto model = std::make_shared<std::string>();
  auto out = std::make_shared<std::string>();
  auto config = std::make_shared<std::string>();
  auto wall = std::make_shared<double>(0.0);
  auto json = std::make_shared<bool>(false);
  cmd->add_option("--points", *points, "Ground points \"x,y x,y ...\" in metres, in order");
  cmd->add_option("--pixels", *pixels,
                  "Image points \"u,v u,v ...\" of the floor's corners (needs --model)");
  cmd->add_option("--green", *green,
                  "Image of the empty enclosure: the largest green floor region (needs --model)");
  cmd->add_option("--model", *model, "Posed .cameramodel (after calibrate ground)");
  cmd->add_option("--wall-height", *wall, "enclosure.wall_height_m written with the polygon");
  cmd->add_option("--out", *out, "Write the enclosure section (YAML) here");
  cmd->add_option("--config", *config, "Station config whose enclosure.floor is replaced in place");
  cmd->add_flag("--json", *json, "Print the polygon as JSON");
  cmd->callback([=] {
    const int sources = !points->empty() + !pixels->empty() + !green->empty();
    if (sources != 1)
      throw InputError("calibrate enclosure", "give exactly one of --points, --pixels, --green");
    GroundPolygon floor;
    if (!points->empty()) {
      floor = calib::FloorPolygonFromPoints(calib::ParsePointList(*points, "--points"), "--points");
    } else {
      if (model->empty()) throw InputError("--model", "needed with --pixels and --green");
      const CameraModel m = CameraModel::Read(*model);
      if (!pixels->empty()) {
        floor = calib::FloorPolygonFromPixels(m, calib::ParsePointList(*pixels, "--pixels"),
                                              "--pixels");
      } else {
        const cv::Mat image = cv::imread(*green, cv::IMREAD_COLOR);
        if (image.empty()) throw InputError(*green, "unreadable image");
        floor = calib::FindGreenFloor(m, image);
      }
    }
    const std::string yaml = calib::EnclosureYaml(floor, *wall);
    if (!out->empty()) {
      std::ofstream f(*out);
      f << yaml;
      if (!f) throw WorkError(*out, "cannot write");
    }
    if (!config->empty()) {
      std::ifstream f(*config);
      if (!f) throw InputError(*config, "cannot read the config");
      std::stringstream text;
      text << f.rdbuf();
      const std::string updated = calib::ReplaceEnclosureFloor(text.str(), floor, *config);
      ReplaceFile(*config, updated, "the config");
    }
    if (*json) {
      nlohmann::json j;
      j["floor"] = nlohmann::json::array();
      for (const auto& v : floor.vertices()) j["floor"].push_back({v.x(), v.y()});
      j["area_m2"] = floor.Area();
      j["wall_height_m"] = *wall;
      std::printf("%s\n", j.dump(2).c_str());
    } else {
      std::printf("%s# %zu vertices, %.4f m^2\n", yaml.c_str(), floor.vertices().size(),
                  floor.Area());
    }
  });
}

void AddWizard(CLI::App& parent) {
  auto* cmd = parent.add_subcommand(
      "wizard", "Guided calibration of one camera: intrinsics, ground, enclosure");
  // What the wizard's and its run's options do not hold: where the frames come from, the
  // outputs, and what becomes a field only once known (the board, its pose, frames from seconds).
  // The other flags are those options' own fields, with their defaults.
  struct Options {
    std::string session, config, camera, board, out, intrinsics, floor_points;
    std::vector<double> pose{0, 0, 0};
    double thickness = 0, still_s = 0.2, floor_still_s = 1.0;
    bool json = false;
    calib::WizardOptions wizard;
    calib::WizardRunOptions run;
  };
  auto o = std::make_shared<Options>();
  cmd->add_option("--session", o->session,
                  "A recorded calibration session (replayed, as fast as it decodes)");
  cmd->add_option("--config", o->config,
                  "Station config: calibrate its camera --camera (live or replay)");
  cmd->add_option("--camera", o->camera,
                  "Camera name (session: default the first; config: required)");
  cmd->add_option(
         "--board", o->board,
         "Board: chessboard:COLSxROWS:SQUARE_M or charuco:COLSxROWS:SQUARE_M:MARKER_M[:DICT]")
      ->required();
  cmd->add_option("--out", o->out,
                  "Output folder: CAMERA.cameramodel, plots, enclosure.yaml, wizard.json")
      ->required();
  cmd->add_option("--intrinsics", o->intrinsics,
                  "Known intrinsics (.cameramodel): start at the ground step");
  cmd->add_option("--board-pose", o->pose,
                  "Floor board's top-left checkered corner on the floor: X Y YAW_DEG")
      ->expected(3);
  cmd->add_option("--board-thickness", o->thickness,
                  "Height of the printed surface above the floor, m");
  cmd->add_option("--floor-points", o->floor_points,
                  "Enclosure floor \"x,y x,y ...\" in ground metres (default: the green floor)");
  cmd->add_option("--min-views", o->wizard.verdict.min_views, "Intrinsics: views needed")
      ->capture_default_str();
  cmd->add_option("--max-views", o->wizard.max_views,
                  "Intrinsics: solve what there is at this many views")
      ->capture_default_str();
  cmd->add_option("--min-coverage", o->wizard.verdict.min_coverage,
                  "Intrinsics: fraction of the image's coverage cells needed")
      ->capture_default_str();
  cmd->add_option("--max-rms", o->wizard.verdict.max_rms_px,
                  "Intrinsics: largest trusted RMS reprojection error, px")
      ->capture_default_str();
  cmd->add_option("--still-px", o->wizard.still_px,
                  "Largest corner motion between frames of a still board, px")
      ->capture_default_str();
  cmd->add_option("--still-seconds", o->still_s,
                  "Intrinsics: the board is still this long before a capture");
  cmd->add_option(
      "--floor-still-seconds", o->floor_still_s,
      "Ground: the floor board still this long (frames' timestamps), then its pose is checked");
  cmd->add_option("--count", o->run.max_frames,
                  "Stop after this many frames (0: the whole session / until done)");
  cmd->add_option("--silent-seconds", o->run.silent_s,
                  "A live camera without a frame this long ends the wizard")
      ->check(CLI::PositiveNumber);
  cmd->add_flag("--json", o->json, "Print the result and the step log as JSON");
  cmd->callback([o] {
    if (o->session.empty() == o->config.empty())
      throw InputError("calibrate wizard", "give exactly one of --session, --config");
    CameraConfig camera;
    if (!o->session.empty()) {
      // A recorded session through the same source a configured replay camera opens.
      const SessionInfo info = ReadSessionInfo(o->session);
      if (info.cameras.empty()) throw InputError(o->session, "the session has no camera");
      camera.name = o->camera.empty() ? info.cameras.front().name : o->camera;
      const bool known = std::any_of(info.cameras.begin(), info.cameras.end(),
                                     [&](const auto& c) { return c.name == camera.name; });
      if (!known)
        throw InputError("--camera", "no camera named \"" + camera.name + "\" in " + o->session);
      camera = ReplayCameraConfig(
          camera.name, {.session = fs::absolute(o->session).string(), .realtime = false});
    } else {
      if (o->camera.empty()) throw InputError("--camera", "needed with --config");
      const StationConfig config = LoadStationConfig(o->config);
      bool found = false;
      for (const auto& c : config.cameras) {
        if (c.name == o->camera) camera = c, found = true;
      }
      if (!found)
        throw InputError("--camera", "no camera named \"" + o->camera + "\" in " + o->config);
    }
    calib::WizardOptions w = o->wizard;
    w.board = calib::ParseBoardSpec(o->board);
    w.max_views = std::max(w.max_views, w.verdict.min_views);
    w.detect.exhaustive = false;  // a live camera's frames without a board must stay cheap
    w.ground_from_board = calib::FloorBoardPose(o->pose[0], o->pose[1], o->pose[2], o->thickness);
    if (!o->floor_points.empty())
      w.floor_points = calib::ParsePointList(o->floor_points, "--floor-points");
    if (!o->intrinsics.empty()) w.intrinsics = CameraModel::Read(o->intrinsics);
    auto source = OpenCameraSource(camera, 0);
    const SourceCamera& sc = source->cameras().at(0);
    const double fps = sc.fps > 0 ? sc.fps : 30.0;
    w.still_frames = std::max(2, static_cast<int>(std::lround(o->still_s * fps)));
    // By the frames' timestamps: a recording replayed as fast as it decodes keeps its own time.
    w.floor_still_s = o->floor_still_s;
    calib::CalibrationWizard wizard(camera.name, sc.width, sc.height, w);
    size_t printed = 0;
    auto print_log = [&] {
      for (; printed < wizard.log().size(); ++printed) {
        const auto& e = wizard.log()[printed];
        const std::string kind = e["event"];
        std::string line = "[" + std::string(e["step"]) + "] frame " +
                           std::to_string(e["frame"].get<int>()) + ": ";
        if (kind == "guidance") {
          std::string say;
          for (const auto& s : e["say"]) say += (say.empty() ? "" : "; ") + s.get<std::string>();
          line += say;
        } else {
          line += kind;
          for (const auto& [k, v] : e.items()) {
            if (k != "event" && k != "frame" && k != "step") line += " " + k + "=" + v.dump();
          }
        }
        if (!o->json) std::printf("%s\n", line.c_str());
      }
      std::fflush(stdout);
    };
    const calib::WizardRunResult ran = calib::RunWizardOnSource(*source, wizard, o->run, print_log);
    const int frames = ran.frames;
    if (ran.silent) {
      std::fprintf(
          stderr, "calibrate wizard: %s delivered no frame for %.1f s; ending with what was seen\n",
          camera.name.c_str(), o->run.silent_s);
    }
    wizard.Finish();
    print_log();
    const nlohmann::json result = calib::WriteWizardOutputs(wizard, o->out, w.verdict);
    if (o->json) {
      std::printf("%s\n", result.dump(2).c_str());
    } else {
      std::printf("%s: %s after %d frames, %d views captured%s\n", camera.name.c_str(),
                  result["verdict"].get<std::string>().c_str(), frames, wizard.views(),
                  result["model"].get<std::string>().empty() ? ", no model written" : "");
      for (const auto& v : wizard.verdicts()) std::printf("  - %s\n", v.c_str());
      if (wizard.report()) std::printf("%s", calib::ToText(*wizard.report()).c_str());
    }
    std::fflush(stdout);
    if (!wizard.board_seen())
      throw InputError(o->board,
                       "no board " + w.board.ToString() + " found in any frame (wrong --board?)");
    if (!wizard.verdicts().empty())
      throw WorkError(o->out, "calibration not complete (see the verdicts above)");
  });
}

}  // namespace

void AddCalibrateCommand(CLI::App& app) {
  auto* cmd =
      app.add_subcommand("calibrate", "Camera calibration: intrinsics, ground plane, enclosure");
  cmd->require_subcommand(1);
  AddIntrinsics(*cmd);
  AddGround(*cmd);
  AddEnclosure(*cmd);
  AddWizard(*cmd);
}

}  // namespace ss::apps
