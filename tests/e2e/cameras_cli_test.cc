// The `spritestation cameras` command: with the libcamera backend built in, `cameras --json`
// lists exactly the cameras libcamera finds (none without hardware). Without the backend
// there is nothing to test here.
#include <gtest/gtest.h>

#include <string>

#include <nlohmann/json.hpp>

#include "tests/support/test_support.h"

#if SPRITESTATION_HAVE_LIBCAMERA
#include "capture/libcamera/libcamera_source.h"

namespace ss {
namespace {

// The JSON array in a command's output: the first line starting with '[' from which the rest
// parses.
nlohmann::json ArrayInOutput(const std::string& output) {
  for (size_t at = 0; at < output.size(); at = output.find('\n', at) + 1) {
    if (output[at] == '[') {
      nlohmann::json j = nlohmann::json::parse(output.substr(at), nullptr, false);
      if (j.is_array()) return j;
    }
    if (output.find('\n', at) == std::string::npos) break;
  }
  return {};
}

TEST(Libcamera, CamerasCommandListsLibcameraCameras) {
  const auto cameras = ListLibcameraCameras();
  const auto r = ss::testing::RunSpritestation("cameras --json");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const nlohmann::json list = ArrayInOutput(r.output);
  ASSERT_TRUE(list.is_array()) << r.output;
  size_t libcamera = 0;
  for (const auto& c : list) libcamera += c["backend"] == "libcamera" ? 1 : 0;
  EXPECT_EQ(libcamera, cameras.size()) << r.output;
}

}  // namespace
}  // namespace ss
#endif  // SPRITESTATION_HAVE_LIBCAMERA
