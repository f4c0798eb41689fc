// spritestation replay SESSION [--realtime] [--loop N] [--json]: replays a
// recorded session through the replay source and prints what was replayed.
// Exit 2 (after the report) when the session is damaged, naming the file and frame.
#include <chrono>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "apps/commands.h"
#include "capture/replay/replay_source.h"
#include "core/error.h"

namespace ss::apps {
namespace {

struct CameraReport {
  uint64_t frames = 0;
  int64_t first_timestamp_ns = 0;
  int64_t last_timestamp_ns = 0;
  uint64_t sequence_gaps = 0;  // frames missing between consecutive delivered sequence numbers
  uint64_t last_sequence = 0;
};

void RunReplay(const std::string& dir, bool realtime, int loops, bool json) {
  ReplayOptions options;
  options.realtime = realtime;
  options.loops = loops;
  ReplaySource source(dir, options);
  const auto& cameras = source.cameras();
  std::vector<CameraReport> report(cameras.size());

  const auto start = std::chrono::steady_clock::now();
  uint64_t total = 0;
  while (auto frame = source.Next()) {
    CameraReport& r = report.at(static_cast<size_t>(frame->camera));
    if (r.frames == 0) {
      r.first_timestamp_ns = frame->timestamp_ns;
    } else if (frame->sequence > r.last_sequence + 1) {
      r.sequence_gaps += frame->sequence - r.last_sequence - 1;
    }
    r.last_timestamp_ns = frame->timestamp_ns;
    r.last_sequence = frame->sequence;
    ++r.frames;
    ++total;
  }
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const double fps = seconds > 0 ? static_cast<double>(total) / seconds : 0.0;
  const auto stats = source.camera_stats();
  const SourceStats totals = source.stats();

  // The recorded span and frame rate of what each camera delivered.
  auto span_s = [&](size_t i) {
    return report[i].frames > 1
               ? static_cast<double>(report[i].last_timestamp_ns - report[i].first_timestamp_ns) /
                     1e9
               : 0.0;
  };
  auto recorded_fps = [&](size_t i) {
    const double span = span_s(i);
    return span > 0 ? static_cast<double>(report[i].frames - 1) / span : 0.0;
  };
  if (json) {
    nlohmann::json out;
    out["session"] = dir;
    out["name"] = source.session().name;
    out["realtime"] = realtime;
    out["loops"] = loops;
    out["cameras"] = nlohmann::json::array();
    for (size_t i = 0; i < cameras.size(); ++i) {
      const auto& c = cameras[i];
      const auto& r = report[i];
      out["cameras"].push_back({{"name", c.name},
                                {"pixel_format", PixelFormatName(c.format)},
                                {"width", c.width},
                                {"height", c.height},
                                {"codec", source.session().cameras[i].codec},
                                {"model", c.model_path},
                                {"frames", r.frames},
                                {"frames_in_csv", stats[i].frames_in_csv},
                                {"first_timestamp_ns", r.first_timestamp_ns},
                                {"last_timestamp_ns", r.last_timestamp_ns},
                                {"span_s", span_s(i)},
                                {"fps", recorded_fps(i)},
                                {"sequence_gaps", r.sequence_gaps},
                                {"recorded_drops", stats[i].recorded_drops},
                                {"frames_unreadable", stats[i].frames_unreadable},
                                {"frames_without_row", stats[i].frames_without_row},
                                {"errors", stats[i].errors},
                                {"problems", stats[i].problems}});
    }
    out["frames"] = total;
    out["seconds"] = seconds;
    out["frames_per_second"] = fps;
    out["errors"] = totals.errors;
    std::printf("%s\n", out.dump(2).c_str());
  } else {
    std::printf("session %s ('%s'), %zu camera(s)%s\n", dir.c_str(), source.session().name.c_str(),
                cameras.size(), realtime ? ", real time" : "");
    std::printf("%-14s %-9s %-10s %-5s %7s %20s %9s %7s %5s %5s %6s\n", "camera", "format", "size",
                "codec", "frames", "first_timestamp_ns", "span_s", "fps", "gaps", "drops",
                "errors");
    for (size_t i = 0; i < cameras.size(); ++i) {
      const auto& c = cameras[i];
      const auto& r = report[i];
      const std::string size = std::to_string(c.width) + "x" + std::to_string(c.height);
      std::printf("%-14s %-9s %-10s %-5s %7llu %20lld %9.3f %7.2f %5llu %5llu %6llu\n",
                  c.name.c_str(), PixelFormatName(c.format).c_str(), size.c_str(),
                  source.session().cameras[i].codec.c_str(),
                  static_cast<unsigned long long>(r.frames),
                  static_cast<long long>(r.first_timestamp_ns), span_s(i), recorded_fps(i),
                  static_cast<unsigned long long>(r.sequence_gaps),
                  static_cast<unsigned long long>(stats[i].recorded_drops),
                  static_cast<unsigned long long>(stats[i].errors));
      for (const auto& p : stats[i].problems) std::printf("  ! %s\n", p.c_str());
    }
    std::printf(
        "(gaps: frames missing between delivered sequence numbers, lost at the device or "
        "unreadable; "
        "drops: the recorder's drops_before)\n");
    std::printf("total: %llu frames replayed in %.3f s = %.1f frames/s\n",
                static_cast<unsigned long long>(total), seconds, fps);
  }
  std::fflush(stdout);
  if (totals.errors > 0) {
    std::string message = totals.last_error;
    if (totals.errors > 1)
      message += " (and " + std::to_string(totals.errors - 1) + " more problem(s), listed above)";
    throw InputError(message);
  }
}

}  // namespace

void AddReplayCommand(CLI::App& app) {
  auto* cmd = app.add_subcommand("replay", "Replay a recorded session and print what was replayed");
  auto dir = std::make_shared<std::string>();
  auto realtime = std::make_shared<bool>(false);
  auto loops = std::make_shared<int>(1);
  auto json = std::make_shared<bool>(false);
  cmd->add_option("session", *dir, "Session folder (holds session.json)")->required();
  cmd->add_flag("--realtime", *realtime, "Pace frames by their original device timestamps");
  cmd->add_option("--loop", *loops, "Passes over the session (0: until interrupted)")
      ->check(CLI::NonNegativeNumber);
  cmd->add_flag("--json", *json, "Print the report as JSON");
  cmd->callback([=] { RunReplay(*dir, *realtime, *loops, *json); });
}

}  // namespace ss::apps
