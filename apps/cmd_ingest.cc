// spritestation ingest SESSION --bank BANK [--config station.yaml] [--no-transitions]
//                     [--transition-weights W] [--decode-threads N] [--json]:
// runs a recorded session through the live pipeline into a sprite bank as fast
// as the machine allows, keeps the bank's transitions current (unless
// --no-transitions) and prints what it kept and what it discarded, by reason.
// A camera none of whose frames could be read, or whose recording is damaged or
// cut short (frames its CSV lists that cannot be read), makes the command exit 1
// naming the file and the frame, after everything readable has been stored.
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "apps/commands.h"
#include "config/station_config.h"
#include "core/error.h"
#include "pipeline/filter/usability.h"
#include "pipeline/run/ingest.h"

namespace ss::apps {
namespace {

void PrintProgress(const IngestProgress& p) {
  const double fraction =
      p.frames_total ? static_cast<double>(p.frames_done) / p.frames_total : 0.0;
  const int width = 30, filled = static_cast<int>(std::lround(fraction * width));
  std::fprintf(stderr, "\r[%s%s] %5.1f%%  %llu/%llu frames  %llu sprites  %.0f frames/s ",
               std::string(filled, '#').c_str(), std::string(width - filled, '.').c_str(),
               100 * fraction, static_cast<unsigned long long>(p.frames_done),
               static_cast<unsigned long long>(p.frames_total),
               static_cast<unsigned long long>(p.sprites_stored),
               p.seconds > 0 ? p.frames_done / p.seconds : 0.0);
  std::fflush(stderr);
}

nlohmann::json DiscardsJson(const DiscardCounts& counts) {
  nlohmann::json j = nlohmann::json::object();
  for (size_t r = 1; r < counts.size(); ++r) j[DiscardName(static_cast<Discard>(r))] = counts[r];
  return j;
}

void RunIngest(const std::string& session, const std::string& bank, const std::string& config_path,
               bool json, bool transitions, const std::string& transition_weights,
               int decode_threads) {
  IngestOptions options{.session_dir = session,
                        .bank_path = bank,
                        .transitions = transitions,
                        .transition_weights = transition_weights,
                        .decode_threads = decode_threads};
  StationConfig config;  // without a file: the config's defaults
  if (!config_path.empty()) {
    ConfigOptions config_options;
    config_options.check_files = false;  // ingest uses keying, enclosure and pipeline only
    config = LoadStationConfig(config_path, nullptr, config_options);
  }
  options.pipeline = config.pipeline;
  options.floor = config.enclosure.floor;
  options.transition_table = {.include_merged = config.transitions.include_merged,
                              .max_per_sprite = config.transitions.max_per_sprite};
  const bool bar = !json && isatty(STDERR_FILENO);
  if (bar) options.progress = PrintProgress;
  const IngestSummary s = IngestSession(options);
  if (bar) std::fprintf(stderr, "\n");
  // The parts of the work that failed while the rest went on: the summary says them, and the
  // command then exits 1 (WorkError) instead of reporting success.
  std::vector<std::string> failed;
  for (const IngestCamera& c : s.cameras) {
    if (c.stats.frames == 0) {
      failed.push_back("camera " + c.name + ": no frame of it could be read" +
                       (s.source.last_error.empty() ? "" : " (" + s.source.last_error + ")"));
    } else if (c.replay.frames_unreadable > 0) {
      // A damaged or cut recording: the frames around the damage are stored, the damage is named.
      failed.push_back("camera " + c.name + ": " + std::to_string(c.replay.frames_unreadable) +
                       " of " + std::to_string(c.replay.frames_in_csv) +
                       " frames could not be read" +
                       (c.replay.problems.empty() ? "" : " (" + c.replay.problems.front() + ")"));
    } else if (c.replay.errors > 0) {
      // Every frame read, yet the recording is not whole (a truncated frames CSV, a session.json
      // that lists more frames than there are): logged as an error, so not a success.
      failed.push_back("camera " + c.name + ": " +
                       (c.replay.problems.empty() ? std::to_string(c.replay.errors) + " problems"
                                                  : c.replay.problems.front()));
    }
  }
  if (s.transitions && !s.transitions_error.empty()) {
    failed.push_back("transitions: " + s.transitions_error + " (run 'spritestation transitions " +
                     bank + "')");
  }
  const auto finish = [&] {
    if (failed.empty()) return;
    std::string what;
    for (const std::string& f : failed) what += (what.empty() ? "" : "; ") + f;
    throw WorkError(session, "ingest stored what it could, but " + what);
  };

  if (json) {
    nlohmann::json out = {{"session", session},
                          {"bank", bank},
                          {"session_id", s.session_id},
                          {"frames", s.frames},
                          {"sprites_kept", s.sprites_kept},
                          {"sprites_merged", s.sprites_merged},
                          {"rows_inserted", s.rows_inserted},
                          {"batches", s.batches},
                          {"px_per_m", s.px_per_m},
                          {"px_per_m_why", s.px_per_m_why},
                          {"discards", DiscardsJson(s.discards)},
                          {"seconds", s.seconds},
                          {"frames_per_second", s.frames_per_second},
                          {"unreadable_frames", s.source.frames_dropped},
                          {"transitions", s.transitions}};
    if (s.transitions) {
      out["transitions_stored"] = s.transitions_stored;
      out["transitions_in_table"] = s.transitions_in_table;
      out["transition_sprites"] = s.transition_sprites;
      out["seconds_transitions_wait"] = s.seconds_transitions_wait;
      out["transitions_error"] = s.transitions_error;
    }
    out["cameras"] = nlohmann::json::array();
    for (const IngestCamera& c : s.cameras) {
      out["cameras"].push_back({{"name", c.name},
                                {"bank_camera_id", c.bank_camera_id},
                                {"frames", c.stats.frames},
                                {"training_frames", c.stats.training_frames},
                                {"candidates", c.stats.candidates},
                                {"sprites_kept", c.stats.stored_sprites},
                                {"sprites_merged", c.stats.merged_sprites},
                                {"clips", c.stats.clips},
                                {"sequence_gaps", c.stats.sequence_gaps},
                                {"discards", DiscardsJson(c.stats.discards)},
                                {"seconds_key", c.stats.seconds_key},
                                {"seconds_rest", c.stats.seconds_rest},
                                {"unreadable_frames", c.replay.frames_unreadable},
                                {"problems", c.replay.problems}});
    }
    out["failed"] = failed;
    std::printf("%s\n", out.dump(2).c_str());
    std::fflush(stdout);
    finish();
    return;
  }
  std::printf("ingested %s into %s\n", session.c_str(), bank.c_str());
  std::printf("  %llu frames in %.2f s (%.0f frames/s)\n",
              static_cast<unsigned long long>(s.frames), s.seconds, s.frames_per_second);
  std::printf(
      "  %llu usable sprites kept (+ as many mirrored copies), %llu new rows in %llu batches%s\n",
      static_cast<unsigned long long>(s.sprites_kept),
      static_cast<unsigned long long>(s.rows_inserted), static_cast<unsigned long long>(s.batches),
      s.rows_inserted == 0 && s.sprites_kept > 0 ? " (already in the bank)" : "");
  if (s.sprites_merged > 0) {
    std::printf(
        "  %llu of them tagged merged (two subjects in one blob; no transitions unless "
        "transitions.include_merged)\n",
        static_cast<unsigned long long>(s.sprites_merged));
  }
  std::printf("  billboard scale %g px/m: %s\n", s.px_per_m, s.px_per_m_why.c_str());
  std::printf("  discarded:");
  for (size_t r = 1; r < s.discards.size(); ++r) {
    std::printf(" %s %llu", DiscardName(static_cast<Discard>(r)),
                static_cast<unsigned long long>(s.discards[r]));
  }
  std::printf("\n");
  for (const IngestCamera& c : s.cameras) {
    std::printf(
        "  %s: %llu frames (%llu learnt as the empty enclosure), %llu candidates, %llu kept in "
        "%llu clips, "
        "key %.2f s, rest %.2f s\n",
        c.name.c_str(), static_cast<unsigned long long>(c.stats.frames),
        static_cast<unsigned long long>(c.stats.training_frames),
        static_cast<unsigned long long>(c.stats.candidates),
        static_cast<unsigned long long>(c.stats.stored_sprites),
        static_cast<unsigned long long>(c.stats.clips), c.stats.seconds_key, c.stats.seconds_rest);
  }
  if (s.transitions) {
    std::printf("  transitions: %lld stored", static_cast<long long>(s.transitions_in_table));
    if (s.transitions_stored > s.transitions_in_table) {
      std::printf(" (of %lld written: the rest past transitions.max_per_sprite out of a sprite)",
                  static_cast<long long>(s.transitions_stored));
    }
    std::printf(" (table of %lld sprites kept current; waited %.2f s at the end)\n",
                static_cast<long long>(s.transition_sprites), s.seconds_transitions_wait);
    if (!s.transitions_error.empty()) {
      std::printf("  transitions FAILED: %s (run 'spritestation transitions %s')\n",
                  s.transitions_error.c_str(), bank.c_str());
    }
  } else {
    std::printf("  transitions: not kept current (--no-transitions)\n");
  }
  if (s.source.frames_dropped > 0) {
    std::printf("  %llu frames could not be read: %s\n",
                static_cast<unsigned long long>(s.source.frames_dropped),
                s.source.last_error.c_str());
  }
  std::fflush(stdout);
  finish();
}

}  // namespace

void AddIngestCommand(CLI::App& app) {
  auto* cmd = app.add_subcommand(
      "ingest", "Run a recorded session through the live pipeline into a sprite bank");
  auto session = std::make_shared<std::string>();
  auto bank = std::make_shared<std::string>();
  auto config = std::make_shared<std::string>();
  auto json = std::make_shared<bool>(false);
  auto transitions = std::make_shared<bool>(true);
  auto weights = std::make_shared<std::string>();
  auto decode_threads = std::make_shared<int>(0);
  cmd->add_option("SESSION", *session, "Recorded session folder")->required();
  cmd->add_option("--bank", *bank, "Sprite bank (created when missing)")->required();
  cmd->add_option("--config", *config, "Station config (keying, enclosure, pipeline sections)");
  cmd->add_flag("--transitions,!--no-transitions", *transitions,
                "Keep the bank's transition table current while ingesting (default on)");
  cmd->add_option("--transition-weights", *weights,
                  "Transition classifier weights (default: the shipped weights)");
  cmd->add_option(
         "--decode-threads", *decode_threads,
         "Decoder threads per camera for FFV1/ffvhuff videos (0: one per core; 1: one decoder, "
         "frames decoded one after another)")
      ->check(CLI::NonNegativeNumber);
  cmd->add_flag("--json", *json, "Print the summary as JSON");
  cmd->callback(
      [=] { RunIngest(*session, *bank, *config, *json, *transitions, *weights, *decode_threads); });
}

}  // namespace ss::apps
