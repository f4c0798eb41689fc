// A config file is read within the input size limit (core/input_file.h).
#include <filesystem>
#include <fstream>
#include <functional>

#include <gtest/gtest.h>

#include "config/station_config.h"
#include "core/error.h"
#include "core/input_file.h"
#include "tests/support/error_text.h"
#include "tests/support/test_support.h"

namespace ss {
namespace {

namespace fs = std::filesystem;
using ss::testing::ScratchDir;

// Issue 20: yaml-cpp parses a whole file first (a 250 MB config took seconds and GBs). The file is
// sparse: refused from its size, before a byte of it is read.
TEST(StationConfig, AFileOverTheLimitIsRefusedBeforeItIsRead) {
  ScratchDir dir;
  const std::string path = dir / "station.yaml";
  std::ofstream(path) << "cameras:\n";
  fs::resize_file(path, 250'000'000);
  EXPECT_EQ(testing::InputErrorOf([&] { LoadStationConfig(path); }),
            path + ": 238.4 MiB (250000000 bytes): larger than the 16 MiB a config file may be");
  fs::resize_file(path, kMaxInputFileBytes + 1);
  EXPECT_EQ(testing::InputErrorOf([&] { LoadStationConfig(path); }),
            path + ": 16.0 MiB (16777217 bytes): larger than the 16 MiB a config file may be");
}

}  // namespace
}  // namespace ss
