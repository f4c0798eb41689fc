// spritestation bench http [--connections=N] [--addresses=A] [--seconds=S]: the station's API
// under a slow-header attack (issue 39). A station replays a small synthetic session on one
// camera behind its HTTP server, as the daemon runs them; a client at 127.0.0.250 asks for
// /api/status every 50 ms on a new connection and times each answer, while N connections
// from A addresses (127.0.0.1 ...) each send a request line and then one header line every
// 2 s, never finishing; whatever the server closes (a 503 over a limit, a 408 at the request
// deadline) the attacker opens again at its next round.
//   http/baseline_polls                 the same polls with no attacker: the figures to beat
//   http/slow_headers_N_from_A          the polls under the attack
// Counters: polls, polls_failed (no answer within 2 s, or not 200), p50/p99/max of a poll in
// ms, attack_connections (opened over the run), attack_refused (503s the attacker read),
// server_open / server_refused (the server's own count at the end: served now, refused in all).
#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/resource.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <string>
#include <thread>
#include <vector>

#include <nlohmann/json.hpp>

#include "bench/bench_registry.h"
#include "capture/replay/replay_source.h"
#include "core/log.h"
#include "pipeline/transitions/transition_jumps.h"  // Quantile
#include "station/control_server.h"
#include "station/station.h"
#include "station/station_host.h"
#include "synth/studio_session.h"
// Last: <resolv.h>, which it includes, defines _res, a name Eigen's headers use.
#include <httplib.h>

namespace ss::bench::http_bench {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

struct HttpBenchArgs {
  int connections = 2000;
  int addresses = 1;
  double seconds = 20;
};
HttpBenchArgs g_args;

// A small synthetic session (one camera, 320x240, 4 s), made once.
std::string Session() {
  const fs::path dir = fs::temp_directory_path() / "spritestation-http-bench-session";
  if (fs::exists(dir / "session.json")) return dir.string();
  fs::remove_all(dir);
  synth::SynthOptions o;
  o.out_dir = dir.string();
  o.seconds = 4;
  o.fps = 30;
  o.width = 320;
  o.height = 240;
  o.cameras = 1;
  o.seed = 5;
  o.empty_lead_in_s = 1.0;
  o.write_mattes = false;
  o.threads = 2;
  synth::RenderStudioSession(o);
  return dir.string();
}

// A TCP connection to 127.0.0.1:port from `address` (a loopback address); -1 when refused.
int ConnectFrom(const std::string& address, int port) {
  const int fd = ::socket(AF_INET, SOCK_STREAM | SOCK_NONBLOCK, 0);
  if (fd < 0) return -1;
  sockaddr_in local{};
  local.sin_family = AF_INET;
  ::inet_pton(AF_INET, address.c_str(), &local.sin_addr);
  sockaddr_in server{};
  server.sin_family = AF_INET;
  server.sin_port = htons(static_cast<uint16_t>(port));
  ::inet_pton(AF_INET, "127.0.0.1", &server.sin_addr);
  if (::bind(fd, reinterpret_cast<sockaddr*>(&local), sizeof local) != 0 ||
      (::connect(fd, reinterpret_cast<sockaddr*>(&server), sizeof server) != 0 &&
       errno != EINPROGRESS)) {
    ::close(fd);
    return -1;
  }
  return fd;
}

// N slow-header connections from A addresses, kept open: one round every 2 s sends each a
// header line and opens again what the server closed.
class SlowHeaders {
 public:
  SlowHeaders(int port, int connections, int addresses)
      : port_(port), fds_(static_cast<size_t>(connections), -1), addresses_(addresses) {
    thread_ = std::thread([this] { Run(); });
  }
  ~SlowHeaders() {
    stop_ = true;
    thread_.join();
    for (const int fd : fds_)
      if (fd >= 0) ::close(fd);
  }
  uint64_t opened() const { return opened_; }
  uint64_t refused() const { return refused_; }

 private:
  void Run() {
    const std::string start = "GET /api/status HTTP/1.1\r\nHost: 127.0.0.1\r\n";
    while (!stop_) {
      for (size_t i = 0; i < fds_.size() && !stop_; ++i) {
        int& fd = fds_[i];
        if (fd >= 0) {
          char buf[512];
          const ssize_t n = ::recv(fd, buf, sizeof buf, MSG_DONTWAIT);
          if (n == 0 || (n < 0 && errno != EAGAIN && errno != EWOULDBLOCK)) {
            ::close(fd);
            fd = -1;
          } else if (n > 0) {
            if (std::string(buf, static_cast<size_t>(n)).rfind("HTTP/1.1 503", 0) == 0) ++refused_;
            ::close(fd);
            fd = -1;
          } else {
            (void)::send(fd, "X-Slow: 1\r\n", 11, MSG_NOSIGNAL | MSG_DONTWAIT);
          }
        }
        if (fd < 0) {
          fd =
              ConnectFrom("127.0.0." + std::to_string(1 + static_cast<int>(i) % addresses_), port_);
          if (fd < 0) continue;
          ++opened_;
          pollfd p{fd, POLLOUT, 0};
          if (::poll(&p, 1, 100) > 0)
            (void)::send(fd, start.data(), start.size(), MSG_NOSIGNAL | MSG_DONTWAIT);
        }
      }
      for (int i = 0; i < 20 && !stop_; ++i)
        std::this_thread::sleep_for(std::chrono::milliseconds(100));
    }
  }

  int port_;
  std::vector<int> fds_;
  int addresses_;
  std::atomic<bool> stop_{false};
  std::atomic<uint64_t> opened_{0}, refused_{0};
  std::thread thread_;
};

void Polls(benchmark::State& state, bool attack) {
  rlimit files{};
  ::getrlimit(RLIMIT_NOFILE, &files);
  files.rlim_cur = files.rlim_max;  // the attacker's and the server's ends of every connection
  ::setrlimit(RLIMIT_NOFILE, &files);
  const std::string session = Session();
  const fs::path work =
      fs::temp_directory_path() / ("spritestation-http-bench-run-" + std::to_string(getpid()));
  fs::remove_all(work);
  fs::create_directories(work);
  for (auto _ : state) {
    StationOptions options;
    StationConfig& config = options.config;
    config.cameras.push_back(
        ReplayCameraConfig("cam0", {.session = session, .loop = true, .realtime = true}));
    config.storage.bank = (work / "station.bank").string();
    config.storage.recording_dir = (work / "recordings").string();
    config.storage.stop_recording_below_mib = 0;
    config.storage.stop_sprites_below_mib = 0;
    config.logging.level = "off";
    config.control.port = 0;
    StationHost host(options, {});
    host.Start();
    ControlServer control(host, ControlServerOptions{config.control});
    const int port = control.Start();
    std::unique_ptr<SlowHeaders> attacker;
    if (attack) {
      attacker = std::make_unique<SlowHeaders>(port, g_args.connections, g_args.addresses);
      std::this_thread::sleep_for(std::chrono::seconds(3));  // the attack in place
    }
    httplib::Client poll("127.0.0.1", port);
    poll.set_interface("127.0.0.250");
    poll.set_connection_timeout(2, 0);
    poll.set_read_timeout(2, 0);
    std::vector<double> ms;
    int failed = 0;
    const auto end = Clock::now() + std::chrono::duration<double>(g_args.seconds);
    while (Clock::now() < end) {
      const auto asked = Clock::now();
      const auto r = poll.Get("/api/status");
      const double took = std::chrono::duration<double, std::milli>(Clock::now() - asked).count();
      if (!r || r->status != 200) {
        ++failed;
      } else {
        ms.push_back(took);
      }
      std::this_thread::sleep_until(asked + std::chrono::milliseconds(50));
    }
    state.counters["polls"] = static_cast<double>(ms.size() + static_cast<size_t>(failed));
    state.counters["polls_failed"] = failed;
    state.counters["p50_ms"] = Quantile(ms, 0.50).value_or(0);
    state.counters["p99_ms"] = Quantile(ms, 0.99).value_or(0);
    state.counters["max_ms"] = ms.empty() ? 0 : *std::max_element(ms.begin(), ms.end());
    if (attacker) {
      state.counters["attack_connections"] = static_cast<double>(attacker->opened());
      state.counters["attack_refused"] = static_cast<double>(attacker->refused());
      // The server's own count: connections it served at the end, and refused over the run.
      if (const auto r = poll.Get("/api/status"); r && r->status == 200) {
        const auto control = nlohmann::json::parse(r->body, nullptr, false)["control"];
        if (control.is_object()) {
          state.counters["server_open"] = control.value("connections_open", 0.0);
          state.counters["server_refused"] = control.value("connections_refused", 0.0);
        }
      }
    }
    attacker.reset();
    control.Stop();
    host.Stop();
  }
  fs::remove_all(work);
}

// Options come as --name=value (the bench command hands extras through in its own order).
int Run(const std::vector<std::string>& args) {
  std::vector<std::string> pass;
  for (const std::string& a : args) {
    const auto [key, value] = OptionNameValue(a);
    if (key == "--connections") {
      g_args.connections = std::max(1, std::stoi(value));
    } else if (key == "--addresses") {
      g_args.addresses = std::clamp(std::stoi(value), 1, 200);
    } else if (key == "--seconds") {
      g_args.seconds = std::stod(value);
    } else {
      pass.push_back(a);
    }
  }
  SetLogLevel("off");
  benchmark::RegisterBenchmark("http/baseline_polls", Polls, false)
      ->Iterations(1)
      ->Unit(benchmark::kSecond)
      ->UseRealTime();
  benchmark::RegisterBenchmark(("http/slow_headers_" + std::to_string(g_args.connections) +
                                "_from_" + std::to_string(g_args.addresses))
                                   .c_str(),
                               Polls, true)
      ->Iterations(1)
      ->Unit(benchmark::kSecond)
      ->UseRealTime();
  return RunGoogleBenchmarks("http/", pass);
}

const bool kRegistered =
    RegisterSuite({"http",
                   "the API under slow-header clients: poll latency and failures "
                   "(--connections= --addresses= --seconds=)",
                   &Run});

}  // namespace
}  // namespace ss::bench::http_bench
