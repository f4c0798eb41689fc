#include "tests/e2e/daemon/station_fixture.h"

#include <fcntl.h>
#include <sched.h>
#include <sys/file.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>

#include "core/bank.h"
#include "core/posix.h"
#include "tests/support/test_support.h"

namespace ss::testing {
namespace {

namespace fs = std::filesystem;

std::string& NetworkError() {
  static std::string error = "the private network was not set up";
  return error;
}

bool WriteFile(const std::string& path, const std::string& text) {
  std::ofstream out(path);
  out << text;
  return static_cast<bool>(out);
}

// A network namespace of this process (and its children): as root directly, else
// inside a user namespace where this user is root. Then lo up with a second address.
std::string EnterPrivateNetwork() {
  if (unshare(CLONE_NEWNET) != 0) {
    const uid_t uid = getuid();
    const gid_t gid = getgid();
    if (unshare(CLONE_NEWUSER | CLONE_NEWNET) != 0) {
      return std::string("unshare(CLONE_NEWUSER | CLONE_NEWNET): ") + ErrnoText(errno) +
             " (the daemon tests need a private network namespace: run as root or enable user "
             "namespaces)";
    }
    WriteFile("/proc/self/setgroups", "deny");
    if (!WriteFile("/proc/self/uid_map", "0 " + std::to_string(uid) + " 1") ||
        !WriteFile("/proc/self/gid_map", "0 " + std::to_string(gid) + " 1")) {
      return "cannot map this user to root in the new user namespace";
    }
  }
  if (testing::RunCommand("ip link set lo up && ip addr add 127.0.0.2/8 dev lo").exit_code != 0) {
    return "`ip link set lo up && ip addr add 127.0.0.2/8 dev lo` failed (is iproute2 installed?)";
  }
  return "";
}

class PrivateNetwork : public ::testing::Environment {
 public:
  void SetUp() override { NetworkError() = EnterPrivateNetwork(); }
};
const auto* const kEnvironment = ::testing::AddGlobalTestEnvironment(new PrivateNetwork);

StationSession MakeSession() {
  StationSession s;
  // Keyed by the executable's build time: a rebuilt pipeline makes its own reference bank.
  const std::optional<std::string> bin = Environment("SPRITESTATION_BIN");
  std::error_code ec;
  const auto built = bin ? fs::last_write_time(*bin, ec).time_since_epoch().count() : 0;
  const fs::path root =
      fs::temp_directory_path() / ("spritestation-station-fixture-" + std::to_string(built));
  fs::create_directories(root);
  s.dir = (root / "session").string();
  s.ingest_bank = (root / "ingest.bank").string();
  // One process makes it, the others wait on the lock and reuse it.
  const int lock = open((root / "lock").c_str(), O_CREAT | O_RDWR, 0644);
  flock(lock, LOCK_EX);
  if (!fs::exists(root / "done")) {
    fs::remove_all(s.dir);
    fs::remove(s.ingest_bank);
    const CommandResult synth =
        RunSpritestation("synth --out " + s.dir +
                         " --kind animal --seconds 5 --fps 30 --size 640x480 --cameras 2"
                         " --subjects 1 --seed 12 --empty-lead-in 2");
    const CommandResult ingest = RunSpritestation("ingest " + s.dir + " --bank " + s.ingest_bank);
    if (synth.exit_code == 0 && ingest.exit_code == 0) {
      WriteFile((root / "done").string(), "ok\n");
    } else {
      ADD_FAILURE() << "making the shared session failed:\n" << synth.output << ingest.output;
    }
  }
  flock(lock, LOCK_UN);
  close(lock);
  std::ifstream floor_file(s.dir + "/truth/floor.json");
  const nlohmann::json floor = nlohmann::json::parse(floor_file, nullptr, false);
  s.floor_yaml = "[";
  if (floor.is_object() && floor.contains("polygon")) {
    for (const auto& p : floor["polygon"]) {
      s.floor_yaml += (s.floor_yaml.size() > 1 ? ", [" : "[") + std::to_string(p[0].get<double>()) +
                      ", " + std::to_string(p[1].get<double>()) + "]";
    }
  }
  s.floor_yaml += "]";
  return s;
}

}  // namespace

const std::string& PrivateNetworkError() { return NetworkError(); }

const StationSession& SharedStationSession() {
  static const StationSession session = MakeSession();
  return session;
}

std::map<std::string, std::map<int64_t, BankSprite>> SpritesByCamera(const std::string& path) {
  Bank bank(path);
  std::map<int64_t, std::string> camera_names;
  for (const CameraRecord& c : bank.ListCameras()) camera_names[c.id] = c.name;
  std::map<int64_t, std::string> clip_camera;
  for (const ClipRecord& c : bank.ListClips()) clip_camera[c.id] = camera_names[c.camera_id];
  std::map<std::string, std::map<int64_t, BankSprite>> out;
  for (const SpriteFeatures& f : bank.LoadFeatures()) {
    if (f.mirrored) continue;
    out[clip_camera[f.clip_id]][f.timestamp_ns] = {f.ground_x_m, f.ground_y_m};
  }
  return out;
}

}  // namespace ss::testing
