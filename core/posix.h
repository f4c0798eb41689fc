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

// The CPU priorities (nice values) of the daemon's threads; on Linux each thread has its own,
// and a thread it starts inherits it. Capture and keying run at the default; the console's
// HTTP threads below them, so a page never takes a core from capture; background bank work
// (the transition worker, a retrain) below the console, so a page stays answerable while
// transitions are found on a busy machine.
constexpr int kNiceHttp = 10;
constexpr int kNiceBackground = 15;

// Sets the calling thread's nice value (best effort: a failure leaves it as it was).
void SetThisThreadNice(int nice);

}  // namespace ss
