#include "tests/support/test_support.h"
#include "core/posix.h"

#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <random>
#include <sstream>
#include <thread>

#include <gtest/gtest.h>
#if defined(__SANITIZE_THREAD__)
#include <opencv2/core/utility.hpp>
#endif

#if defined(__SANITIZE_THREAD__)
namespace {
// Under ThreadSanitizer (scripts/tsan.sh) OpenCV runs parallel_for_ bodies on the calling thread:
// its TBB pool synchronises in code TSan does not see, so every body run on a pool thread was
// reported as racing with its caller. The run is about our own threads.
const bool kOpenCvSerial = [] {
  cv::setNumThreads(0);
  return true;
}();
}  // namespace
#endif

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
  if (!Environment("SPRITESTATION_KEEP_SCRATCH")) std::filesystem::remove_all(path_, ec);
}

std::string SourcePath(const std::string& relative) {
  return (std::filesystem::path(SPRITESTATION_SOURCE_DIR) / relative).string();
}

std::string SpritestationCommand(const std::string& args) {
  return Environment("SPRITESTATION_BIN").value_or("spritestation") + " " + args;
}

CommandResult RunSpritestation(const std::string& args) {
  return RunCommand(SpritestationCommand(args));
}

bool RunSpritestationOk(const std::string& args) {
  const CommandResult r = RunSpritestation("--log-level warn " + args);
  EXPECT_EQ(r.exit_code, 0) << args << "\n" << r.output;
  return r.exit_code == 0;
}

CommandResult RunCommand(const std::string& shell_command) {
  const std::string command = shell_command + " 2>&1";
  CommandResult result;
  FILE* pipe = popen(command.c_str(), "r");
  if (!pipe) return result;
  std::array<char, 4096> buffer{};
  size_t n = 0;
  while ((n = fread(buffer.data(), 1, buffer.size(), pipe)) > 0)
    result.output.append(buffer.data(), n);
  const int status = pclose(pipe);
  result.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  return result;
}

BackgroundCommand::BackgroundCommand(const std::string& args, const std::string& log_path)
    : log_path_(log_path) {
  const std::string command = "exec " + Environment("SPRITESTATION_BIN").value_or("spritestation") +
                              " " + args + " > '" + log_path + "' 2>&1";
  pid_ = fork();
  if (pid_ == 0) {
    execl("/bin/sh", "sh", "-c", command.c_str(), static_cast<char*>(nullptr));
    _exit(127);
  }
}

BackgroundCommand::~BackgroundCommand() {
  if (running()) {
    kill(pid_, SIGKILL);
    Wait(10);
  }
}

bool BackgroundCommand::running() {
  if (pid_ <= 0 || status_ != -1) return false;
  int status = 0;
  if (waitpid(pid_, &status, WNOHANG) == pid_) {
    status_ = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
    return false;
  }
  return true;
}

std::string BackgroundCommand::output() const {
  std::ifstream in(log_path_);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

bool BackgroundCommand::WaitForOutput(const std::string& text, double timeout_s) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
  while (std::chrono::steady_clock::now() < deadline) {
    if (output().find(text) != std::string::npos) return true;
    if (!running()) return output().find(text) != std::string::npos;
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  return false;
}

void BackgroundCommand::Signal(int signal) {
  if (running()) kill(pid_, signal);
}

int BackgroundCommand::Wait(double timeout_s) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
  while (running()) {
    if (std::chrono::steady_clock::now() >= deadline) return -1;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  return status_;
}

nlohmann::json JsonInOutput(const std::string& output) {
  const size_t line_start = output.find("\n{");
  const size_t begin = line_start == std::string::npos ? output.find('{') : line_start + 1;
  const size_t end = output.rfind('}');
  if (begin == std::string::npos || end == std::string::npos || end < begin) return {};
  return nlohmann::json::parse(output.substr(begin, end - begin + 1), nullptr, false);
}

}  // namespace ss::testing
