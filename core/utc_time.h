#pragma once
// The wall clock as text, in UTC: when sessions, recordings, labels and calibrations were made.
#include <string>

namespace ss {

// "2026-12-01T06:35:12Z": for records and JSON.
std::string UtcNowIso();
// "20261201T063512Z": for folder and file names (sorts by time, no ':').
std::string UtcNowStamp();

}  // namespace ss
