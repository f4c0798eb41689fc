#pragma once
// Helpers shared by the test suites: scratch folders and running the executable.
#include <filesystem>
#include <string>

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

// Runs `spritestation ARGS` (the binary named by $SPRITESTATION_BIN) through the shell.
CommandResult RunSpritestation(const std::string& args);

// The JSON document in a command's output (log lines may surround it); null when there is none.
nlohmann::json JsonInOutput(const std::string& output);

}  // namespace ss::testing
