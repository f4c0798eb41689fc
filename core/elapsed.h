#pragma once
// Seconds of the steady clock, as the reports and the logs print them.
#include <chrono>

namespace ss {

// A steady-clock duration in seconds.
inline double Seconds(std::chrono::steady_clock::duration d) {
  return std::chrono::duration<double>(d).count();
}
// Seconds on the steady clock since its (arbitrary) epoch: for differences only.
inline double MonotonicSeconds() {
  return Seconds(std::chrono::steady_clock::now().time_since_epoch());
}
// Seconds from `start` until now, on the steady clock.
inline double SecondsSince(std::chrono::steady_clock::time_point start) {
  return Seconds(std::chrono::steady_clock::now() - start);
}

}  // namespace ss
