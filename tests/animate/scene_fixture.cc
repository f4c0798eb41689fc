// The scene tests' fixture of scene_fixture.h: its files and specs.
#include "tests/animate/scene_fixture.h"

#include <fstream>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include "tests/animate/animate_test_bank.h"

namespace ss::testing {

void SceneTest::SetUp() {
  WalkerBank::Write(dir_ / "walker.ssbank");
  LookAtCamera(320, 240, 300, {0.5, -3, 2.5}, {0.5, 0.5, 0}).Write(dir_ / "virtual.cameramodel");
  cv::imwrite(dir_ / "floor.png", cv::Mat(240, 320, CV_8UC3, cv::Scalar(90, 140, 170)));
}

std::string SceneTest::WriteSpec(const std::string& body) {
  std::string path = dir_ / "scene.yaml";
  std::ofstream out(path);
  out << "camera: virtual.cameramodel\nbackground: floor.png\nbanks: [walker.ssbank]\n" << body;
  return path;
}

}  // namespace ss::testing
