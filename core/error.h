#pragma once
// The two kinds of error a user sees. Both carry a message that names the file
// or field at fault; apps/ maps them to exit codes (InputError -> 2, WorkError -> 1).
#include <stdexcept>
#include <string>

namespace ss {

// Bad input the user can fix: a missing or corrupt file, a wrong config field, bad usage.
class InputError : public std::runtime_error {
 public:
  explicit InputError(const std::string& what) : std::runtime_error(what) {}
  // "PATH: REASON" — the form every file-related message takes.
  InputError(const std::string& path, const std::string& reason)
      : std::runtime_error(path + ": " + reason) {}
};

// The work itself failed (an I/O error mid-run, a solver that did not converge, a full disk).
class WorkError : public std::runtime_error {
 public:
  explicit WorkError(const std::string& what) : std::runtime_error(what) {}
  WorkError(const std::string& path, const std::string& reason)
      : std::runtime_error(path + ": " + reason) {}
};

}  // namespace ss
