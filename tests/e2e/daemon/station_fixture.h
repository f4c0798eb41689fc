#pragma once
// What every daemon test shares: a private network namespace (so each test
// process has its own loopback with 127.0.0.1 and 127.0.0.2, and two emulated
// GigE cameras can serve on port 3956 without meeting another test's), one
// synthetic session and the bank `spritestation ingest` makes of it.
#include <cstdint>
#include <map>
#include <string>

#include <nlohmann/json.hpp>

namespace ss::testing {

// Set up once per test process (a gtest Environment): empty when it worked, else why not.
const std::string& PrivateNetworkError();

struct StationSession {
  std::string dir;          // the synthetic session (2 cameras, 640x480, 30 fps, 2 s empty lead-in)
  std::string ingest_bank;  // `spritestation ingest` of it
  std::string floor_yaml;   // its floor polygon as a YAML flow list
};
// Made once and shared by every test process (under a file lock).
const StationSession& SharedStationSession();

// Original sprites of a bank per camera name: timestamp_ns -> (ground x, ground y).
struct BankSprite {
  double ground_x = 0, ground_y = 0;
};
std::map<std::string, std::map<int64_t, BankSprite>> SpritesByCamera(const std::string& bank);

}  // namespace ss::testing
