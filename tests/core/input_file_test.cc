#include "core/input_file.h"

#include <filesystem>
#include <fstream>
#include <functional>
#include <sstream>

#include <gtest/gtest.h>

#include "core/error.h"
#include "tests/support/error_text.h"
#include "tests/support/test_support.h"

namespace ss {
namespace {

namespace fs = std::filesystem;
using ss::testing::ScratchDir;

TEST(ReadWithinLimit, ReadsAFileUpToTheLimitAndRefusesOneByteMore) {
  ScratchDir dir;
  const std::string path = dir / "f.yaml";
  std::ofstream(path) << std::string(1000, 'a');
  std::ifstream in(path);
  EXPECT_EQ(ReadWithinLimit(in, path, "a config file", 1000), std::string(1000, 'a'));

  std::ofstream(path) << std::string(1001, 'a');
  std::ifstream again(path);
  EXPECT_EQ(testing::InputErrorOf([&] { ReadWithinLimit(again, path, "a config file", 1000); }),
            path + ": 1001 bytes: larger than the 1000 bytes a config file may be");
}

// What has no size (a pipe, a device, a stream) is counted as it is read.
TEST(ReadWithinLimit, CountsWhatHasNoSizeWhileReading) {
  std::istringstream endless(std::string(3u << 20, '#'));
  EXPECT_EQ(testing::InputErrorOf(
                [&] { ReadWithinLimit(endless, "(a pipe)", "an animation spec", 1u << 20); }),
            "(a pipe): more than 1 MiB read: larger than the 1 MiB an animation spec may be");
  std::istringstream small("cameras: []\n");
  EXPECT_EQ(ReadWithinLimit(small, "(a pipe)", "a config file", 1u << 20), "cameras: []\n");
}

}  // namespace
}  // namespace ss
