#pragma once
// The scene tests' fixture, shared by tests/animate/scene_test.cc (the optimizer) and
// tests/e2e/animate_cli_test.cc (the `animate` and `render` commands): a scratch folder with
// the synthetic walker bank, a virtual camera and a floor image, and the scene specs over them.
#include <string>

#include <gtest/gtest.h>

#include "tests/support/test_support.h"

namespace ss::testing {

class SceneTest : public ::testing::Test {
 protected:
  // Writes walker.ssbank, virtual.cameramodel and floor.png into dir_.
  void SetUp() override;
  // Writes dir_/scene.yaml: the camera, background and bank above, then `body`; its path.
  std::string WriteSpec(const std::string& body);
  ScratchDir dir_;
};

}  // namespace ss::testing
