// spritestation bench NAME [args...]: runs one benchmark suite (see bench/).
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "apps/commands.h"
#include "core/error.h"

#ifdef SPRITESTATION_HAVE_BENCH
#include "bench/bench_registry.h"
#endif

namespace ss::apps {

void AddBenchCommand(CLI::App& app) {
  auto* cmd = app.add_subcommand("bench", "Run a benchmark suite and print its figures");
  auto name = std::make_shared<std::string>();
  auto args = std::make_shared<std::vector<std::string>>();
  auto list = std::make_shared<bool>(false);
  cmd->add_flag("--list", *list, "List the suites");
  cmd->add_option("suite", *name, "Suite to run");
  cmd->add_option("args", *args, "Arguments passed to the suite (e.g. --benchmark_min_time=1)");
  cmd->allow_extras();
  cmd->callback([name, args, list, cmd] {
#ifdef SPRITESTATION_HAVE_BENCH
    std::vector<std::string> all = *args;
    for (const auto& extra : cmd->remaining()) all.push_back(extra);
    if (*list || name->empty()) {
      for (const auto& s : bench::Suites())
        std::printf("%-14s %s\n", s.name.c_str(), s.summary.c_str());
      return;
    }
    for (const auto& s : bench::Suites()) {
      if (s.name == *name) {
        const int rc = s.run(all);
        if (rc != 0) throw WorkError("bench " + *name + " exited with " + std::to_string(rc));
        return;
      }
    }
    throw InputError("bench", "no suite named '" + *name + "' (see spritestation bench --list)");
#else
    (void)cmd;
    throw InputError("bench",
                     "this build has no benchmarks (scripts/demo.sh leaves them out): build them "
                     "in with SPRITESTATION_BENCHMARKS=ON scripts/build.sh");
#endif
  });
}

}  // namespace ss::apps
