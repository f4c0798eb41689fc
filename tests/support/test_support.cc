#include "tests/support/test_support.h"

#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <cstdio>
#include <cstdlib>
#include <random>

#include <gtest/gtest.h>

namespace ss::testing {

ScratchDir::ScratchDir() {
  std::random_device rd;
  const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
  std::string name = info ? std::string(info->test_suite_name()) + "." + info->name() : "scratch";
  for (char& c : name) {
    if (c == '/') c = '_';
  }
  path_ = std::filesystem::temp_directory_path() /
          ("spritestation-" + name + "-" + std::to_string(getpid()) + "-" + std::to_string(rd()));
  std::filesystem::create_directories(path_);
}

ScratchDir::~ScratchDir() {
  std::error_code ec;
  if (std::getenv("SPRITESTATION_KEEP_SCRATCH") == nullptr) std::filesystem::remove_all(path_, ec);
}

CommandResult RunSpritestation(const std::string& args) {
  const char* bin = std::getenv("SPRITESTATION_BIN");
  const std::string command = std::string(bin ? bin : "spritestation") + " " + args + " 2>&1";
  CommandResult result;
  FILE* pipe = popen(command.c_str(), "r");
  if (!pipe) return result;
  std::array<char, 4096> buffer{};
  size_t n = 0;
  while ((n = fread(buffer.data(), 1, buffer.size(), pipe)) > 0) result.output.append(buffer.data(), n);
  const int status = pclose(pipe);
  result.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  return result;
}

nlohmann::json JsonInOutput(const std::string& output) {
  const size_t line_start = output.find("\n{");
  const size_t begin = line_start == std::string::npos ? output.find('{') : line_start + 1;
  const size_t end = output.rfind('}');
  if (begin == std::string::npos || end == std::string::npos || end < begin) return {};
  return nlohmann::json::parse(output.substr(begin, end - begin + 1), nullptr, false);
}

}  // namespace ss::testing
