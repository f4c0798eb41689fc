// spritestation: the one executable. Exit codes: 0 success, 1 the work failed,
// 2 bad usage or bad input. Errors name the file or field and the reason.
#include <cerrno>
#include <csignal>
#include <cstdio>
#include <string>
#include <system_error>

#include <CLI/CLI.hpp>

#include "apps/commands.h"
#include "core/error.h"
#include "core/log.h"

namespace {

int Run(int argc, char** argv) {
  CLI::App app{"SpriteStation: live capture and recording of video sprites"};
  app.require_subcommand(1);
  std::string log_level = "info";
  app.add_option("--log-level", log_level, "trace, debug, info, warn, error, off")
      ->check(CLI::IsMember({"trace", "debug", "info", "warn", "error", "critical", "off"}));
  app.parse_complete_callback([&] { ss::SetLogLevel(log_level); });

  ss::apps::AddSynthCommand(app);
  ss::apps::AddCalibrateCommand(app);
  ss::apps::AddReplayCommand(app);
  ss::apps::AddPlateCommand(app);
  ss::apps::AddBankCommand(app);
  ss::apps::AddIngestCommand(app);
  ss::apps::AddBenchCommand(app);
  ss::apps::AddConfigCommand(app);
  ss::apps::AddAnimateCommand(app);
  ss::apps::AddRenderCommand(app);
  ss::apps::AddJudgeCommand(app);
  ss::apps::AddFakecamCommand(app);
  ss::apps::AddCamerasCommand(app);
  ss::apps::AddSkeletonCommand(app);
  ss::apps::AddMatchCommand(app);
  ss::apps::AddTransitionsCommand(app);
  ss::apps::AddDaemonCommand(app);
  ss::apps::AddImportCommand(app);

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int code = app.exit(e);
    return code == 0 ? 0 : 2;
  } catch (const ss::InputError& e) {
    std::fprintf(stderr, "spritestation: error: %s\n", e.what());
    return 2;
  } catch (const ss::WorkError& e) {
    std::fprintf(stderr, "spritestation: failed: %s\n", e.what());
    return 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "spritestation: failed: %s\n", e.what());
    return 1;
  }
  return 0;
}

// What was printed reached standard output, or the command fails saying why (a closed pipe,
// a full disk): a reader must not take a cut-off listing for the whole.
int CheckStdout(int code) {
  if (std::fflush(stdout) == 0 && !std::ferror(stdout)) return code;
  const int err = errno;
  std::fprintf(
      stderr, "spritestation: failed: standard output: %s\n",
      err != 0 ? std::error_code(err, std::generic_category()).message().c_str() : "write error");
  return code == 0 ? 1 : code;
}

}  // namespace

int main(int argc, char** argv) {
  // A file grown past its size limit (ulimit -f, a quota) and a closed pipe are errors that name
  // their file, not signals that kill the process without a word: write() then fails with EFBIG
  // or EPIPE, and the writer that called it (SQLite, FFmpeg, our own) reports the file.
  std::signal(SIGXFSZ, SIG_IGN);
  std::signal(SIGPIPE, SIG_IGN);
  // Nothing escapes: what Run's handlers do not name (an exception while the commands are set
  // up, one that is not a std::exception) still ends with a message and exit 1, not abort().
  try {
    return CheckStdout(Run(argc, argv));
  } catch (const std::exception& e) {
    std::fprintf(stderr, "spritestation: failed: %s\n", e.what());
  } catch (...) {
    std::fprintf(stderr, "spritestation: failed: an unknown error\n");
  }
  return 1;
}
