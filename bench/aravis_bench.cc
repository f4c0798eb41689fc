// spritestation bench aravis [--seconds S]: frames/s and CPU per frame received
// through the Aravis backend from the emulated GigE camera over loopback.
// The camera runs as a separate `spritestation fakecam` process (asked for
// 1000 frames/s, so it sends as fast as it can fill), so the CPU measured here
// is the receiver's alone: Aravis's stream thread reassembling GVSP packets
// plus the FrameSource loop. Baseline, same run: one memcpy of a frame of the
// same size, so "CPU per frame" also reads as a multiple of a plain copy.
#include <signal.h>
#include <spawn.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <string>
#include <thread>
#include <vector>

#include <benchmark/benchmark.h>

#include "bench/bench_registry.h"
#include "capture/recording/session_writer.h"
#ifdef SPRITESTATION_HAVE_ARAVIS
#include "capture/aravis/aravis_source.h"
#endif

extern char** environ;

namespace ss::bench::aravis_bench {
namespace {

#ifdef SPRITESTATION_HAVE_ARAVIS
namespace fs = std::filesystem;

constexpr int kW = 640;
constexpr int kH = 480;
constexpr int kSessionFrames = 30;

double CpuSeconds() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return static_cast<double>(u.ru_utime.tv_sec + u.ru_stime.tv_sec) +
         static_cast<double>(u.ru_utime.tv_usec + u.ru_stime.tv_usec) * 1e-6;
}

// A green-screen-like session: a lit backdrop with a moving block and some noise.
void RecordSession(const std::string& dir, PixelFormat format) {
  SourceCamera cam;
  cam.name = "cam0";
  cam.width = kW;
  cam.height = kH;
  cam.format = format;
  cam.fps = 30;
  SessionWriter writer(dir, "bench-aravis");
  const int index = writer.AddCamera(cam, nullptr);
  const size_t bpp = FrameBytes(format, 1, 1);
  uint32_t seed = 7;
  for (int i = 0; i < kSessionFrames; ++i) {
    std::vector<uint8_t> px(FrameBytes(format, kW, kH));
    for (int y = 0; y < kH; ++y) {
      for (int x = 0; x < kW; ++x) {
        const bool subject = x > 100 + 10 * i && x < 220 + 10 * i && y > 120 && y < 440;
        for (size_t c = 0; c < bpp; ++c) {
          seed = seed * 1664525u + 1013904223u;
          const int base =
              subject ? 120 + 30 * static_cast<int>(c) : (c == 1 || bpp == 1 ? 170 : 50);
          px[(static_cast<size_t>(y) * kW + x) * bpp + c] =
              static_cast<uint8_t>(base + ((seed >> 28) & 3));
        }
      }
    }
    Frame f = Frame::Owned(format, kW, kH, std::move(px));
    f.camera = index;
    f.sequence = static_cast<uint64_t>(i);
    f.timestamp_ns = i * 33'333'333LL;
    writer.Write(f);
  }
  writer.Close();
}

struct Result {
  double fps = 0;
  double mib_per_s = 0;
  double cpu_us_per_frame = 0;
  uint64_t frames = 0;
  uint64_t dropped = 0;
  uint64_t resent = 0;
};

Result Measure(const std::string& session, PixelFormat format, int packet_size, double seconds) {
  const std::string self = fs::read_symlink("/proc/self/exe").string();
  std::vector<std::string> args = {self,      "--log-level", "warn",      "fakecam",
                                   session,   "--address",   "127.0.0.1", "--serial",
                                   "SSBENCH", "--fps",       "1000"};
  std::vector<char*> argv;
  argv.reserve(args.size() + 1);  // and the nullptr
  for (auto& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  pid_t pid = 0;
  if (posix_spawn(&pid, self.c_str(), nullptr, nullptr, argv.data(), environ) != 0) {
    std::fprintf(stderr, "cannot start %s fakecam\n", self.c_str());
    return {};
  }
  Result r;
  try {
    AravisOptions o;
    o.camera = "127.0.0.1";
    o.packet_size = packet_size;
    o.buffers = 32;
    std::unique_ptr<AravisSource> source;
    for (int attempt = 0; !source; ++attempt) {  // the camera needs a moment to bind
      try {
        source = std::make_unique<AravisSource>(o);
      } catch (const std::exception&) {
        if (attempt > 50) throw;
        std::this_thread::sleep_for(std::chrono::milliseconds(100));
      }
    }
    for (int i = 0; i < 10; ++i) source->Next();  // warm up
    const auto before = source->stats();
    const double cpu0 = CpuSeconds();
    const auto t0 = std::chrono::steady_clock::now();
    double elapsed = 0;
    while (elapsed < seconds) {
      auto f = source->Next();
      if (!f) break;
      ++r.frames;
      elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    }
    const double cpu = CpuSeconds() - cpu0;
    const auto after = source->stats();
    r.fps = static_cast<double>(r.frames) / elapsed;
    r.mib_per_s = r.fps * static_cast<double>(FrameBytes(format, kW, kH)) / (1024.0 * 1024.0);
    r.cpu_us_per_frame = r.frames > 0 ? cpu * 1e6 / static_cast<double>(r.frames) : 0;
    r.dropped = after.frames_dropped - before.frames_dropped;
    r.resent = source->stream_stats().resent_packets;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "aravis bench: %s\n", e.what());
  }
  kill(pid, SIGTERM);
  int status = 0;
  waitpid(pid, &status, 0);
  return r;
}

double MemcpyUsPerFrame(size_t bytes) {
  std::vector<uint8_t> a(bytes, 1), b(bytes);
  const int n = 2000;
  const double cpu0 = CpuSeconds();
  for (int i = 0; i < n; ++i) {
    a[static_cast<size_t>(i) % bytes] = static_cast<uint8_t>(i);
    std::memcpy(b.data(), a.data(), bytes);
    benchmark::DoNotOptimize(b.data());
    benchmark::ClobberMemory();
  }
  const double cpu = CpuSeconds() - cpu0;
  return cpu * 1e6 / n;
}

int Run(const std::vector<std::string>& args) {
  double seconds = 3.0;
  for (size_t i = 0; i + 1 < args.size(); ++i) {
    if (args[i] == "--seconds") seconds = std::stod(args[i + 1]);
  }
  const fs::path dir =
      fs::temp_directory_path() / ("spritestation-aravis-bench-" + std::to_string(getpid()));
  fs::create_directories(dir);
  struct Case {
    const char* name;
    PixelFormat format;
    int packet_size;
  };
  const Case cases[] = {{"mono8_640x480_packet8000", PixelFormat::kMono8, 8000},
                        {"rgb8_640x480_packet8000", PixelFormat::kRGB8, 8000},
                        {"mono8_640x480_packet1500", PixelFormat::kMono8, 1500},
                        {"rgb8_640x480_packet1500", PixelFormat::kRGB8, 1500}};
  std::printf("%-28s %9s %9s %14s %14s %8s %8s\n", "aravis/case", "frames/s", "MiB/s",
              "cpu_us/frame", "x_memcpy", "dropped", "resent");
  for (const auto& c : cases) {
    const std::string session = (dir / PixelFormatName(c.format)).string();
    if (!fs::exists(session)) RecordSession(session, c.format);
    const Result r = Measure(session, c.format, c.packet_size, seconds);
    const double base = MemcpyUsPerFrame(FrameBytes(c.format, kW, kH));
    std::printf("%-28s %9.1f %9.1f %14.1f %14.1f %8llu %8llu\n", c.name, r.fps, r.mib_per_s,
                r.cpu_us_per_frame, base > 0 ? r.cpu_us_per_frame / base : 0.0,
                static_cast<unsigned long long>(r.dropped),
                static_cast<unsigned long long>(r.resent));
    std::fflush(stdout);
  }
  std::error_code ec;
  fs::remove_all(dir, ec);
  return 0;
}
#else
int Run(const std::vector<std::string>&) {
  std::fprintf(stderr, "bench aravis: this build has no Aravis support\n");
  return 1;
}
#endif

const bool registered = RegisterSuite(
    {"aravis",
     "frames/s and CPU per frame through the Aravis backend from the emulated GigE camera", &Run});

}  // namespace
}  // namespace ss::bench::aravis_bench
