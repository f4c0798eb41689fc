// The control API's request bodies parsed alone (station/request_bodies.h): each route's valid
// body gives its request, and bad ones are refused with an InputError naming the field.
#include "station/request_bodies.h"

#include <gtest/gtest.h>

#include "core/error.h"

namespace ss::api {
namespace {

// The field an InputError names ("field: reason"), or "(parsed)" when none was thrown.
template <typename F>
std::string FieldOf(F&& parse) {
  try {
    parse();
  } catch (const InputError& e) {
    const std::string what = e.what();
    return what.substr(0, what.find(':'));
  }
  return "(parsed)";
}

nlohmann::json Body(const std::string& text, std::initializer_list<const char*> fields) {
  return ObjectBody(text, fields);
}

TEST(RequestBodies, ObjectBodyTakesAnObjectWithTheRoutesMembersOnly) {
  EXPECT_EQ(Body("", kSessionFields), nlohmann::json::object());
  EXPECT_EQ(Body(R"({"name": "a"})", kSessionFields)["name"], "a");
  EXPECT_EQ(FieldOf([] { Body("{\"name\": ", kSessionFields); }), "body");
  EXPECT_EQ(FieldOf([] { Body("[1]", kSessionFields); }), "body");
  EXPECT_EQ(FieldOf([] { Body(R"({"nmae": "a"})", kSessionFields); }), "nmae");
  EXPECT_EQ(FieldOf([] { Body(R"({"x": 1})", {}); }), "x");
}

// Issue 20's fuzzing: 1 MiB of brackets (what the server lets in) overflowed the HTTP thread's
// stack when the error message quoted the value (nlohmann::json writes by recursion), and the
// daemon died. Bodies nest 32 levels at most; the API needs 3.
TEST(RequestBodies, ADeeplyNestedBodyIsRefusedWhileItIsParsed) {
  const auto nested = [](size_t depth) {
    return R"({"name": )" + std::string(depth, '[') + std::string(depth, ']') + "}";
  };
  const std::string deep = nested(524000);
  ASSERT_LE(deep.size(), 1u << 20);
  try {
    ObjectBody(deep, kSessionFields);
    ADD_FAILURE() << "parsed";
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(), "body: nested deeper than 32 levels");
  }
  EXPECT_EQ(FieldOf([&] { ObjectBody(nested(32), kSessionFields); }), "body");
  const nlohmann::json deepest = ObjectBody(nested(31), kSessionFields);  // the object is level 1
  EXPECT_EQ(FieldOf([&] { ParseSessionName(deepest, true, false); }), "name");
}

TEST(RequestBodies, SessionReplayAndTagRequests) {
  EXPECT_EQ(ParseSessionName(Body(R"({"name": "take 1"})", kSessionFields), true, false), "take 1");
  EXPECT_EQ(ParseSessionName(Body("", kSessionFields), false, true), "");
  EXPECT_EQ(FieldOf([] { ParseSessionName(Body("", kSessionFields), true, true); }), "body");
  EXPECT_EQ(FieldOf([] { ParseSessionName(Body("{}", kSessionFields), true, false); }), "name");
  EXPECT_EQ(FieldOf([] { ParseSessionName(Body(R"({"name": 1})", kSessionFields), false, false); }),
            "name");

  const ReplayStartRequest replay =
      ParseReplayStart(Body(R"({"path": "/s", "loop": true})", kReplayStartFields));
  EXPECT_EQ(replay.path, "/s");
  EXPECT_TRUE(replay.paced);
  EXPECT_TRUE(replay.loop);
  EXPECT_EQ(
      FieldOf([] { ParseReplayStart(Body(R"({"path": "/s", "paced": 1})", kReplayStartFields)); }),
      "paced");

  const TagRequest sprites = ParseTag(Body(R"({"tag": "walk", "sprites": [3, 4]})", kTagFields));
  EXPECT_EQ(sprites.sprites, (std::vector<int64_t>{3, 4}));
  const TagRequest run = ParseTag(
      Body(R"({"tag": "walk", "clip": 2, "first_frame": 5, "last_frame": 9})", kTagFields));
  EXPECT_TRUE(run.sprites.empty());
  EXPECT_EQ(run.clip, 2);
  EXPECT_EQ(run.last_frame, 9);
  EXPECT_EQ(FieldOf([] { ParseTag(Body(R"({"tag": "a b", "sprites": [1]})", kTagFields)); }),
            "tag");
  EXPECT_EQ(FieldOf([] { ParseTag(Body(R"({"tag": "a", "sprites": []})", kTagFields)); }),
            "sprites");
  EXPECT_EQ(
      FieldOf([] {
        ParseTag(Body(R"({"tag": "a", "clip": 1, "first_frame": 5, "last_frame": 4})", kTagFields));
      }),
      "last_frame");
}

TEST(RequestBodies, LabelRequests) {
  const LabelRequest label =
      ParseLabel(Body(R"({"from": 1, "to": 2, "label": "yes"})", kLabelFields));
  EXPECT_EQ(label.from, 1);
  EXPECT_EQ(label.to, 2);
  EXPECT_EQ(label.label, "yes");
  EXPECT_EQ(
      FieldOf([] { ParseLabel(Body(R"({"from": 0, "to": 2, "label": "yes"})", kLabelFields)); }),
      "from");
  EXPECT_EQ(
      FieldOf([] { ParseLabel(Body(R"({"from": 2, "to": 2, "label": "yes"})", kLabelFields)); }),
      "to");
  EXPECT_EQ(
      FieldOf([] { ParseLabel(Body(R"({"from": 1, "to": 2, "label": "maybe"})", kLabelFields)); }),
      "label");
  EXPECT_EQ(ParseLabelUndo(Body(R"({"from": 7, "to": 8})", kLabelUndoFields)).to, 8);
}

TEST(RequestBodies, CalibrationWizardRequests) {
  const auto cam0 = [](const std::string& name) { return name == "cam0"; };
  const CalibrationStartRequest start = ParseCalibrationStart(
      Body(R"({"board": "chessboard:10x7:0.03", "cameras": ["cam0", "cam0"], "min_views": 5,
               "board_pose": [0.1, 0.2, 90], "use_current_intrinsics": true})",
           kCalibrationStartFields),
      cam0);
  EXPECT_EQ(start.board.squares_x, 10);
  EXPECT_EQ(start.cameras, std::vector<std::string>{"cam0"});
  EXPECT_EQ(start.min_views, 5);
  EXPECT_FALSE(start.max_views);
  EXPECT_EQ(start.board_pose[2], 90);
  EXPECT_TRUE(start.use_current_intrinsics);
  const auto start_field = [&](const std::string& text) {
    return FieldOf([&] { ParseCalibrationStart(Body(text, kCalibrationStartFields), cam0); });
  };
  EXPECT_EQ(start_field(R"({"cameras": ["cam0"]})"), "board");
  EXPECT_EQ(start_field(R"({"board": "chessboard:2x7:0.03"})"), "board");
  EXPECT_EQ(start_field(R"({"board": "chessboard:10x7:0.03", "min_views": 1})"), "min_views");
  EXPECT_EQ(start_field(R"({"board": "chessboard:10x7:0.03", "board_pose": [1, 2]})"),
            "board_pose");
  EXPECT_EQ(start_field(R"({"board": "chessboard:10x7:0.03", "cameras": ["cam9"]})"), "cameras");

  const CalibrationDropRequest drop =
      ParseCalibrationDrop(Body(R"({"camera": "cam0"})", kCalibrationDropFields));
  EXPECT_EQ(drop.which, "last");
  EXPECT_EQ(drop.camera, "cam0");
  EXPECT_EQ(FieldOf([] {
              ParseCalibrationDrop(
                  Body(R"({"camera": "cam0", "which": "best"})", kCalibrationDropFields));
            }),
            "which");
  EXPECT_EQ(
      FieldOf([] { ParseCalibrationDrop(Body(R"({"which": "worst"})", kCalibrationDropFields)); }),
      "camera");

  EXPECT_FALSE(ParseCameraName(Body("", kCalibrationSolveFields), false));
  EXPECT_EQ(
      FieldOf([] { ParseCameraName(Body(R"({"camera": 3})", kCalibrationSolveFields), false); }),
      "camera");

  const CalibrationRedoRequest redo =
      ParseCalibrationRedo(Body(R"({"step": "ground"})", kCalibrationRedoFields));
  EXPECT_EQ(redo.step, calib::WizardStep::kGround);
  EXPECT_FALSE(redo.camera);
  EXPECT_EQ(
      FieldOf([] { ParseCalibrationRedo(Body(R"({"step": "done"})", kCalibrationRedoFields)); }),
      "step");

  EXPECT_TRUE(
      ParseCalibrationFloor(Body(R"({"camera": "cam0", "detect": true})", kCalibrationFloorFields))
          .detect);
  const CalibrationFloorRequest floor = ParseCalibrationFloor(
      Body(R"({"camera": "cam0", "pixels": [[1, 2], [3, 4], [5, 6.5]]})", kCalibrationFloorFields));
  ASSERT_EQ(floor.pixels.size(), 3u);
  EXPECT_EQ(floor.pixels[2], Eigen::Vector2d(5, 6.5));
  EXPECT_EQ(
      FieldOf([] { ParseCalibrationFloor(Body(R"({"pixels": [[1]]})", kCalibrationFloorFields)); }),
      "pixels");
  EXPECT_EQ(FieldOf([] {
              ParseCalibrationFloor(Body(R"({"camera": "cam0"})", kCalibrationFloorFields));
            }),
            "body");
  EXPECT_EQ(FieldOf([] {
              ParseCalibrationFloor(
                  Body(R"({"camera": "cam0", "detect": false})", kCalibrationFloorFields));
            }),
            "body");
  // Found by fuzzing: a "detect" that is not a boolean let nlohmann::json's type_error escape
  // (500).
  EXPECT_EQ(
      FieldOf([] {
        ParseCalibrationFloor(Body(R"({"camera": "cam0", "detect": 1})", kCalibrationFloorFields));
      }),
      "detect");
}

}  // namespace
}  // namespace ss::api
