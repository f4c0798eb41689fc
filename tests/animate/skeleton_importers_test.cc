// The importers on small files written by hand in each tool's published layout
// (tests/data/skeleton/): DeepLabCut analysis and labelled-data CSVs (single and
// multi-animal), OpenPose BODY_25 per-frame JSON, COCO person keypoints, the synthetic
// studio's joint truth; and the joint
// mapping's errors.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <functional>

#include <nlohmann/json.hpp>

#include "animate/skeleton/importers.h"
#include "animate/skeleton/joint_mapping.h"
#include "animate/skeleton/skeleton_json.h"
#include "core/error.h"
#include "tests/support/error_text.h"
#include "tests/support/test_support.h"

namespace ss {
namespace {

std::string Data(const std::string& name) {
  return ss::testing::SourcePath("tests/data/skeleton/" + name);
}

// Expects joint `name` of `frame` at (x, y).
void ExpectJoint(const SkeletonSequence& s, int frame, const std::string& name, float x, float y) {
  SCOPED_TRACE("frame " + std::to_string(frame) + " joint " + name);
  const auto j = s.skeleton.JointIndex(name);
  ASSERT_TRUE(j.has_value());
  const JointSample& sample = s.frames.at(frame).joints.at(*j);
  ASSERT_TRUE(sample.present);
  EXPECT_NEAR(sample.x_px, x, 1e-3);
  EXPECT_NEAR(sample.y_px, y, 1e-3);
}

bool Present(const SkeletonSequence& s, int frame, const std::string& name) {
  return s.frames.at(frame).joints.at(*s.skeleton.JointIndex(name)).present;
}

TEST(SkeletonImporters, DeepLabCutAnalysisCsv) {
  const JointMapping mapping = LoadJointMapping(Data("mouse_mapping.json"));
  EXPECT_EQ(mapping.skeleton.name, "mouse5");
  const SkeletonSequence s = ImportDeepLabCutCsv(Data("dlc_mouse.csv"), mapping);
  ASSERT_EQ(s.size(), 4);
  EXPECT_EQ(s.frames[3].frame, 3);
  ExpectJoint(s, 0, "snout", 300.5f, 120.25f);
  ExpectJoint(s, 0, "neck", 280.0f, 120.0f);  // the mean of both ears
  ExpectJoint(s, 1, "forepaw", 276.0f, 150.0f);
  EXPECT_NEAR(s.frames[0].joints[1].confidence, 0.97f, 1e-6);  // the ears' lower likelihood
  EXPECT_FALSE(Present(s, 2, "hindpaw"));  // likelihood 0.31 < DeepLabCut's pcutoff 0.6
  EXPECT_TRUE(Present(s, 2, "snout"));
  EXPECT_FALSE(Present(s, 3, "snout"));  // 0.45
  // An explicit threshold wins.
  SkeletonImportOptions loose;
  loose.min_confidence = 0.3f;
  const SkeletonSequence l = ImportDeepLabCutCsv(Data("dlc_mouse.csv"), mapping, loose);
  ExpectJoint(l, 2, "hindpaw", 224.0f, 154.0f);
  ExpectJoint(l, 3, "snout", 315.0f, 123.0f);
}

TEST(SkeletonImporters, DeepLabCutMultiAnimalCsv) {
  const JointMapping mapping = LoadJointMapping(Data("mouse_mapping.json"));
  const SkeletonSequence first = ImportDeepLabCutCsv(Data("madlc_mice.csv"), mapping);
  ASSERT_EQ(first.size(), 2);
  ExpectJoint(first, 0, "snout", 100.0f, 50.0f);
  SkeletonImportOptions second;
  second.individual = "mus2";
  const SkeletonSequence s = ImportDeepLabCutCsv(Data("madlc_mice.csv"), mapping, second);
  ExpectJoint(s, 0, "snout", 400.0f, 300.0f);
  ExpectJoint(s, 1, "neck", 388.0f, 301.0f);
  EXPECT_FALSE(Present(s, 1, "forepaw"));  // empty cells (NaN in pandas)
  second.individual = "mus3";
  EXPECT_THROW(ImportDeepLabCutCsv(Data("madlc_mice.csv"), mapping, second), InputError);
}

TEST(SkeletonImporters, DeepLabCutLabelledDataCsv) {
  // CollectedData_<scorer>.csv: three leading columns (folder, video, image), x and y only.
  const JointMapping mapping = LoadJointMapping(Data("mouse_mapping.json"));
  const SkeletonSequence s = ImportDeepLabCutCsv(Data("dlc_collected.csv"), mapping);
  ASSERT_EQ(s.size(), 2);
  EXPECT_EQ(s.frames[1].frame, 1);
  ExpectJoint(s, 0, "neck", 280.0f, 120.0f);
  ExpectJoint(s, 1, "hindpaw", 219.0f, 153.0f);
  EXPECT_FALSE(Present(s, 1, "forepaw"));  // not labelled
}

TEST(SkeletonImporters, OpenPoseBody25Folder) {
  const SkeletonSequence s = ImportOpenPoseJson(Data("openpose_ymca"), Body25ToHuman14());
  ASSERT_EQ(s.size(), 3);
  EXPECT_EQ(s.frames[2].frame, 2);  // from the file name's frame number
  ExpectJoint(s, 0, "head", 320, 100);
  ExpectJoint(s, 0, "wrist_l", 395, 70);  // LWrist: the subject's left
  ExpectJoint(s, 0, "wrist_r", 245, 70);
  ExpectJoint(s, 0, "pelvis", 320, 240);
  for (const auto& j : s.frames[1].joints) EXPECT_FALSE(j.present);  // nobody detected
  ExpectJoint(s, 2, "neck", 324, 140);                               // person 0, not person 1
  EXPECT_FALSE(Present(s, 2, "wrist_l"));                            // c = 0.1 < 0.2
  SkeletonImportOptions other;
  other.person = 1;
  const SkeletonSequence p1 = ImportOpenPoseJson(Data("openpose_ymca"), Body25ToHuman14(), other);
  ExpectJoint(p1, 2, "neck", 520, 150);
  // One file alone.
  const SkeletonSequence one =
      ImportOpenPoseJson(Data("openpose_ymca/ymca_000000000000_keypoints.json"), Body25ToHuman14());
  ASSERT_EQ(one.size(), 1);
  ExpectJoint(one, 0, "knee_r", 303, 310);
}

TEST(SkeletonImporters, CocoPersonKeypoints) {
  const SkeletonSequence s =
      ImportCocoKeypoints(Data("coco_person_keypoints.json"), Coco17ToHuman14());
  ASSERT_EQ(s.size(), 3);
  EXPECT_EQ(s.frames[0].frame, 7);  // image ids
  EXPECT_EQ(s.frames[2].frame, 9);
  ExpectJoint(s, 0, "neck", 320, 140);    // shoulders' midpoint
  ExpectJoint(s, 0, "pelvis", 320, 240);  // hips' midpoint
  ExpectJoint(s, 0, "elbow_l", 380, 180);
  // Image 8: the annotation with the most labelled keypoints, not the small one.
  ExpectJoint(s, 1, "head", 326, 102);
  ExpectJoint(s, 1, "wrist_l", 398, 216);  // v = 1 (hidden) is kept at the default 0.5
  EXPECT_NEAR(s.frames[1].joints[*s.skeleton.JointIndex("wrist_l")].confidence, 0.5f, 1e-6);
  EXPECT_FALSE(Present(s, 1, "ankle_r"));                            // v = 0
  for (const auto& j : s.frames[2].joints) EXPECT_FALSE(j.present);  // image 9: no annotation
  SkeletonImportOptions visible_only;
  visible_only.min_confidence = 0.9f;
  EXPECT_FALSE(Present(
      ImportCocoKeypoints(Data("coco_person_keypoints.json"), Coco17ToHuman14(), visible_only), 1,
      "wrist_l"));
}

TEST(SkeletonImporters, ImportedSequenceRoundTripsThroughJson) {
  const SkeletonSequence s =
      ImportDeepLabCutCsv(Data("dlc_mouse.csv"), LoadJointMapping(Data("mouse_mapping.json")));
  testing::ScratchDir dir;
  WriteSkeletonSequence(s, dir / "mouse.json");
  const SkeletonSequence back = ReadSkeletonSequence(dir / "mouse.json");
  EXPECT_EQ(back.skeleton.name, "mouse5");
  EXPECT_EQ(back.skeleton.joints, s.skeleton.joints);
  ASSERT_EQ(back.size(), s.size());
  for (int f = 0; f < s.size(); ++f) {
    for (size_t j = 0; j < s.skeleton.joints.size(); ++j) {
      EXPECT_EQ(back.frames[f].joints[j].present, s.frames[f].joints[j].present);
      if (s.frames[f].joints[j].present) {
        EXPECT_NEAR(back.frames[f].joints[j].x_px, s.frames[f].joints[j].x_px, 1e-3);
      }
    }
  }
}

TEST(SkeletonImporters, ErrorsNameTheFileAndTheReason) {
  testing::ScratchDir dir;
  // A mapping onto a keypoint the file does not have.
  nlohmann::json bad = nlohmann::json::parse(std::ifstream(Data("mouse_mapping.json")));
  bad["joints"]["forepaw"] = "forepawR";
  std::ofstream(dir / "bad_mapping.json") << bad.dump();
  const JointMapping bad_mapping = LoadJointMapping(dir / "bad_mapping.json");
  const std::string e =
      testing::InputErrorOf([&] { ImportDeepLabCutCsv(Data("dlc_mouse.csv"), bad_mapping); });
  EXPECT_NE(e.find("bad_mapping.json"), std::string::npos) << e;
  EXPECT_NE(e.find("'forepaw'"), std::string::npos) << e;
  EXPECT_NE(e.find("'forepawR'"), std::string::npos) << e;
  // A mapping naming a joint the skeleton lacks.
  bad = nlohmann::json::parse(std::ifstream(Data("mouse_mapping.json")));
  bad["joints"]["tail_tip"] = "tailbase";
  std::ofstream(dir / "unknown_joint.json") << bad.dump();
  EXPECT_NE(testing::InputErrorOf([&] {
              LoadJointMapping(dir / "unknown_joint.json");
            }).find("no joint named 'tail_tip'"),
            std::string::npos);
  // A DeepLabCut row with a column missing.
  std::ifstream in(Data("dlc_mouse.csv"));
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  text.erase(text.rfind(','));
  std::ofstream(dir / "short.csv") << text << "\n";
  const std::string s = testing::InputErrorOf([&] {
    ImportDeepLabCutCsv(dir / "short.csv", LoadJointMapping(Data("mouse_mapping.json")));
  });
  EXPECT_NE(s.find("short.csv: line 7"), std::string::npos) << s;
  // Not the expected format at all.
  EXPECT_NE(testing::InputErrorOf([&] {
              ImportDeepLabCutCsv(Data("coco_person_keypoints.json"), Body25ToHuman14());
            }).find("not a DeepLabCut CSV"),
            std::string::npos);
  EXPECT_NE(testing::InputErrorOf([&] {
              ImportCocoKeypoints(Data("openpose_ymca/ymca_000000000000_keypoints.json"),
                                  Coco17ToHuman14());
            }).find("no 'annotations' array"),
            std::string::npos);
  EXPECT_NE(testing::InputErrorOf([&] {
              ImportOpenPoseJson(Data("coco_person_keypoints.json"), Body25ToHuman14());
            }).find("no 'people' array"),
            std::string::npos);
}

// Issue 39: what sizes the work is bounded. An image id of 2^63 became frame
// -9223372036854775808, and a COCO file of 1.5 M images took 3.4 GB; now an id that is not a
// frame number and a file over 64 MiB are refused by name before the work.
TEST(SkeletonImporters, FrameNumbersAndFileSizesAreBounded) {
  testing::ScratchDir dir;
  nlohmann::json coco = nlohmann::json::parse(std::ifstream(Data("coco_person_keypoints.json")));
  coco["annotations"][0]["image_id"] = uint64_t{1} << 63;
  std::ofstream(dir / "huge_id.json") << coco.dump();
  std::string e =
      testing::InputErrorOf([&] { ImportCocoKeypoints(dir / "huge_id.json", Coco17ToHuman14()); });
  EXPECT_NE(e.find("huge_id.json: annotations[0]: image_id 9223372036854775808 is not a frame "
                   "number (0..2147483647)"),
            std::string::npos)
      << e;
  coco = nlohmann::json::parse(std::ifstream(Data("coco_person_keypoints.json")));
  coco["images"] = nlohmann::json::array({{{"id", -4}}});
  std::ofstream(dir / "negative_id.json") << coco.dump();
  e = testing::InputErrorOf(
      [&] { ImportCocoKeypoints(dir / "negative_id.json", Coco17ToHuman14()); });
  EXPECT_NE(e.find("images[0]: id -4 is not a frame number"), std::string::npos) << e;
  // 65 MiB of JSON whitespace around the small file: refused before it is parsed
  {
    std::ofstream big(dir / "big.json");
    big << std::string(65 << 20, ' ')
        << nlohmann::json::parse(std::ifstream(Data("coco_person_keypoints.json"))).dump();
  }
  e = testing::InputErrorOf([&] { ImportCocoKeypoints(dir / "big.json", Coco17ToHuman14()); });
  EXPECT_NE(e.find("big.json: holds 65 MiB; a skeleton file is at most 64 MiB"), std::string::npos)
      << e;
}

// The synthetic studio's joint truth (docs/synth.md layout), written by hand: two subjects,
// two frames, an extra column the importer must ignore, rows out of joint order.
TEST(SkeletonImporters, SynthJointTruth) {
  ss::testing::ScratchDir dir;
  const std::filesystem::path session = dir.path() / "sess";
  std::filesystem::create_directories(session / "truth" / "cam1");
  std::ofstream(session / "session.json") << R"({"name": "figure-7", "format_version": 1})";
  std::ofstream(session / "truth" / "truth.json")
      << R"({"fps": 12.5, "cameras": [{"name": "cam1"}]})";
  {
    std::ofstream csv(session / "truth" / "cam1" / "joints.csv");
    csv << "frame,subject,joint,name,x,y,hidden\n";
    const auto& names = HumanSkeleton().joints;
    for (int f = 0; f < 2; ++f) {
      for (int subject = 1; subject >= 0; --subject) {
        for (int j = static_cast<int>(names.size()) - 1; j >= 0; --j) {
          csv << f << "," << subject << "," << j << "," << names[j] << ","
              << 100 * subject + 10 * j + f << "," << 200 + j << ",0\n";
        }
      }
    }
  }
  SkeletonImportOptions options;
  options.person = 1;
  const SkeletonSequence s =
      ImportSynthTruth(session.string(), "", IdentityMapping(HumanSkeleton()), options);
  ASSERT_EQ(s.size(), 2);
  EXPECT_EQ(s.clip, "figure-7/cam1");
  EXPECT_DOUBLE_EQ(s.fps, 12.5);
  EXPECT_EQ(s.skeleton.name, "human14");
  ExpectJoint(s, 0, "head", 100, 200);
  ExpectJoint(s, 1, "wrist_l", 141, 204);
  ExpectJoint(s, 1, "ankle_r", 241, 214);
  // The CSV itself works too, subject 0 by default; a subject that is not there is an error.
  const SkeletonSequence s0 = ImportSynthTruth((session / "truth" / "cam1" / "joints.csv").string(),
                                               "", IdentityMapping(HumanSkeleton()));
  ExpectJoint(s0, 1, "neck", 11, 201);
  options.person = 5;
  EXPECT_THROW(ImportSynthTruth(session.string(), "", IdentityMapping(HumanSkeleton()), options),
               InputError);
  EXPECT_THROW(ImportSynthTruth(dir.path().string(), "", IdentityMapping(HumanSkeleton())),
               InputError);
}

}  // namespace
}  // namespace ss
