#pragma once
// The C library's process-wide calls, made safe to use from any thread (clang-tidy's
// concurrency-mt-unsafe): errno's text, and the environment.
#include <optional>
#include <string>

namespace ss {

// The text of an errno value ("No space left on device"), from strerror_r.
std::string ErrnoText(int err);

// The environment variable `name`, or nullopt when it is not set. The project reads the
// environment only: nothing in it calls setenv while threads run (the tests that set a
// variable for a child process do so on gtest's one thread, before the child starts).
std::optional<std::string> Environment(const char* name);

}  // namespace ss
