// The control API's request bodies (station/request_bodies.h): the bytes are a POST body as the
// server receives it (anything: not UTF-8, nested deep, numbers too large), and every route's
// parser takes it, as its handler does: ObjectBody with the route's members, then the route's
// request. A refusal must be an InputError, and the server's answer to it (the message in a JSON
// reply) must be writable.
#include <nlohmann/json.hpp>

#include "station/request_bodies.h"
#include "tests/fuzz/fuzz_support.h"

namespace {

using namespace ss::api;

// One route: its body parsed as its handler parses it.
template <typename F>
void Route(const std::string& text, std::initializer_list<const char*> fields, F&& parse) {
  try {
    parse(ObjectBody(text, fields));
  } catch (const ss::InputError& e) {
    (void)Dump(nlohmann::json{{"error", e.what()}}, 2);  // api::ReplyError's body
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text = ss::fuzz::Text(data, size);
  const auto known_camera = [](const std::string& name) {
    return name == "cam0" || name == "cam1";
  };
  // session/stop, replay/stop, calibration/cancel, calibration/save, labels/retrain: no members.
  Route(text, {}, [](const nlohmann::json&) {});
  Route(text, kSessionFields,
        [&](const nlohmann::json& b) { ParseSessionName(b, false, text.empty()); });  // start
  Route(text, kSessionFields,
        [&](const nlohmann::json& b) { ParseSessionName(b, true, text.empty()); });  // rename
  Route(text, kReplayStartFields, [](const nlohmann::json& b) { ParseReplayStart(b); });
  Route(text, kTagFields, [](const nlohmann::json& b) { ParseTag(b); });  // bank/tag, bank/untag
  Route(text, kLabelFields, [](const nlohmann::json& b) { ParseLabel(b); });
  Route(text, kLabelUndoFields, [](const nlohmann::json& b) { ParseLabelUndo(b); });
  Route(text, kCalibrationStartFields,
        [&](const nlohmann::json& b) { ParseCalibrationStart(b, known_camera); });
  Route(text, kCalibrationDropFields, [](const nlohmann::json& b) { ParseCalibrationDrop(b); });
  Route(text, kCalibrationSolveFields, [](const nlohmann::json& b) { ParseCameraName(b, false); });
  Route(text, kCalibrationRedoFields, [](const nlohmann::json& b) { ParseCalibrationRedo(b); });
  Route(text, kCalibrationFloorFields, [](const nlohmann::json& b) {
    ParseCameraName(b, true);
    ParseCalibrationFloor(b);
  });
  return 0;
}
