#pragma once
// The JSON bodies of the control API's POST routes (docs/daemon.md, docs/console.md), each
// parsed into its request by a pure function: no server, station or bank, so that they are
// tested and fuzzed alone (tests/fuzz/request_bodies_fuzz.cc). A handler takes its body with
// ObjectBody (the route's members, k...Fields), makes the checks that come first (the station is
// running, a wizard is active), then parses it here; what the request means for the station (a
// camera that does not exist, a sprite not in the bank) is then the handler's to check.
// Every function throws InputError naming the field, and nothing else.
#include <cstdint>
#include <functional>
#include <initializer_list>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <nlohmann/json.hpp>

#include "calib/board.h"
#include "calib/wizard_step.h"

namespace ss::api {

// JSON text of `j`; bytes that are not UTF-8 (a request may send anything) are replaced.
std::string Dump(const nlohmann::json& j, int indent = -1);

// The body's text as a JSON object (empty text: {}); InputError naming the field for anything
// else, a member not in `fields`, or arrays and objects nested deeper than kMaxBodyDepth.
inline constexpr int kMaxBodyDepth = 32;  // every body the API takes needs 3
nlohmann::json ObjectBody(const std::string& text, std::initializer_list<const char*> fields);

// POST /api/session/start, /api/session/rename {"name": S}: the name, "" when absent and not
// `required` (then a body that was empty, `sent_empty`, is named "body", else "name").
inline constexpr std::initializer_list<const char*> kSessionFields = {"name"};
std::string ParseSessionName(const nlohmann::json& body, bool required, bool sent_empty);

// POST /api/replay/start {"path": P, "paced": true, "loop": false}.
inline constexpr std::initializer_list<const char*> kReplayStartFields = {"path", "paced", "loop"};
struct ReplayStartRequest {
  std::string path;
  bool paced = true;
  bool loop = false;
};
ReplayStartRequest ParseReplayStart(const nlohmann::json& body);

// POST /api/bank/tag, /api/bank/untag {"tag", "sprites": [ids]} | {"tag", "clip", "first_frame",
// "last_frame"} (a run of a clip's frames).
inline constexpr std::initializer_list<const char*> kTagFields = {"tag", "sprites", "clip",
                                                                  "first_frame", "last_frame"};
struct TagRequest {
  std::string tag;               // 1 to 64 letters, digits, '-', '_', '.'
  std::vector<int64_t> sprites;  // the sprites; empty: the clip's frames below
  int64_t clip = 0, first_frame = 0, last_frame = 0;
};
inline constexpr size_t kMaxTagSprites = 100000;  // sprite ids in one request
TagRequest ParseTag(const nlohmann::json& body);

// POST /api/labels {"from": ID, "to": ID, "label": "yes" | "no" | "skip"}, and /api/labels/undo
// {"from": ID, "to": ID} (label ""): a transition's label, between two sprites (ids >= 1).
inline constexpr std::initializer_list<const char*> kLabelFields = {"from", "to", "label"};
inline constexpr std::initializer_list<const char*> kLabelUndoFields = {"from", "to"};
struct LabelRequest {
  int64_t from = 0, to = 0;
  std::string label;
};
LabelRequest ParseLabel(const nlohmann::json& body);
LabelRequest ParseLabelUndo(const nlohmann::json& body);

// The calibration wizard's steps (POST /api/calibration/...).
// The camera a request names ("camera"); nullopt when it names none and may (every camera).
std::optional<std::string> ParseCameraName(const nlohmann::json& body, bool required);

// POST /api/calibration/start {"board", "cameras", "board_pose", "board_thickness_m", "min_views",
// "max_views", "min_coverage", "max_rms_px", "still_s", "floor_still_s", "use_current_intrinsics"}.
// Absent numbers are nullopt (the handler's defaults). `known_camera` says whether the station has
// a camera of that name.
inline constexpr std::initializer_list<const char*> kCalibrationStartFields = {
    "board",
    "cameras",
    "board_pose",
    "board_thickness_m",
    "min_views",
    "max_views",
    "min_coverage",
    "max_rms_px",
    "still_s",
    "floor_still_s",
    "use_current_intrinsics"};
struct CalibrationStartRequest {
  calib::BoardSpec board;
  std::optional<double> min_views, max_views, min_coverage, max_rms_px, still_s, floor_still_s;
  double board_pose[3] = {0, 0, 0};  // x_m, y_m, yaw_deg of the board lying on the floor
  std::optional<double> board_thickness_m;
  bool use_current_intrinsics = false;
  std::vector<std::string> cameras;  // each once, in the order given; empty: every camera
};
CalibrationStartRequest ParseCalibrationStart(
    const nlohmann::json& body, const std::function<bool(const std::string&)>& known_camera);

// POST /api/calibration/drop {"camera", "which": "last" | "worst"}.
inline constexpr std::initializer_list<const char*> kCalibrationDropFields = {"camera", "which"};
struct CalibrationDropRequest {
  std::string which;   // "last" | "worst"
  std::string camera;  // required
};
CalibrationDropRequest ParseCalibrationDrop(const nlohmann::json& body);

// POST /api/calibration/solve {"camera"} (every camera in the intrinsics step when none).
inline constexpr std::initializer_list<const char*> kCalibrationSolveFields = {"camera"};

// POST /api/calibration/ground {"camera"}: the operator's word that the board lies on the floor
// now (every camera in the ground step when none names one); parsed with ParseCameraName.
inline constexpr std::initializer_list<const char*> kCalibrationGroundFields = {"camera"};

// POST /api/calibration/redo {"camera", "step": "intrinsics" | "ground" | "enclosure"}.
inline constexpr std::initializer_list<const char*> kCalibrationRedoFields = {"camera", "step"};
struct CalibrationRedoRequest {
  calib::WizardStep step;
  std::optional<std::string> camera;  // nullopt: every camera
};
CalibrationRedoRequest ParseCalibrationRedo(const nlohmann::json& body);

// POST /api/calibration/floor {"camera", "detect": true} | {"camera", "pixels": [[x, y], ...]}:
// what follows the camera (ParseCameraName(body, true) comes first).
inline constexpr std::initializer_list<const char*> kCalibrationFloorFields = {"camera", "detect",
                                                                               "pixels"};
struct CalibrationFloorRequest {
  bool detect = false;                  // find the green floor in the camera's frame
  std::vector<Eigen::Vector2d> pixels;  // else: the floor's corners in the camera's pixels
};
CalibrationFloorRequest ParseCalibrationFloor(const nlohmann::json& body);

}  // namespace ss::api
