#pragma once
// Helpers shared by the test suites: scratch folders and running the executable.
#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace ss::testing {

// A fresh folder under the build tree's temp dir, removed when the object dies.
class ScratchDir {
 public:
  ScratchDir();
  ~ScratchDir();
  ScratchDir(const ScratchDir&) = delete;
  ScratchDir& operator=(const ScratchDir&) = delete;
  const std::filesystem::path& path() const { return path_; }
  std::string operator/(const std::string& name) const { return (path_ / name).string(); }

 private:
  std::filesystem::path path_;
};

struct CommandResult {
  int exit_code = -1;
  std::string output;  // stdout and stderr together
};

// True when one of `lines` contains `text` (guidance, problem lists, gap lists).
inline bool AnyContains(const std::vector<std::string>& lines, const std::string& text) {
  for (const std::string& line : lines) {
    if (line.find(text) != std::string::npos) return true;
  }
  return false;
}

// A file of the source tree, by its path from the top ("docs/station.example.yaml"):
// absolute, whatever the working directory or the compiler's idea of __FILE__.
std::string SourcePath(const std::string& relative);

// Runs `spritestation ARGS` (the binary named by $SPRITESTATION_BIN) through the shell.
CommandResult RunSpritestation(const std::string& args);
// Runs `spritestation --log-level warn ARGS` and expects it to succeed (a failure shows the
// arguments and the output); whether it did.
bool RunSpritestationOk(const std::string& args);
// The shell command RunSpritestation runs (the executable, $SPRITESTATION_BIN, and `args`), for a
// test that runs it under another command (prlimit, a redirection).
std::string SpritestationCommand(const std::string& args);
// Runs a shell command (sqlite3, ffprobe ...): its exit code and output (stdout, then stderr).
CommandResult RunCommand(const std::string& command);

// `spritestation ARGS` running in the background (daemon, fakecam); stdout and
// stderr go to `log_path`. Killed (SIGKILL) when the object dies.
class BackgroundCommand {
 public:
  BackgroundCommand(const std::string& args, const std::string& log_path);
  ~BackgroundCommand();
  BackgroundCommand(const BackgroundCommand&) = delete;
  BackgroundCommand& operator=(const BackgroundCommand&) = delete;

  // Waits until the output holds `text`; false on timeout or when the process ended first.
  bool WaitForOutput(const std::string& text, double timeout_s);
  std::string output() const;
  void Signal(int signal);
  // Waits for the exit: the exit code, 128 + signal when killed, -1 on timeout.
  int Wait(double timeout_s);
  bool running();
  int pid() const { return pid_; }

 private:
  int pid_ = -1;
  int status_ = -1;
  std::string log_path_;
};

// The JSON document in a command's output (log lines may surround it); null when there is none.
nlohmann::json JsonInOutput(const std::string& output);

}  // namespace ss::testing
