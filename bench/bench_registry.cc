#include "bench/bench_registry.h"

#include <benchmark/benchmark.h>

namespace ss::bench {

static std::vector<Suite>& Registry() {
  static std::vector<Suite> suites;
  return suites;
}

std::pair<std::string, std::string> OptionNameValue(const std::string& arg) {
  const size_t eq = arg.find('=');
  return {arg.substr(0, eq), eq == std::string::npos ? "" : arg.substr(eq + 1)};
}

bool RegisterSuite(Suite suite) {
  Registry().push_back(std::move(suite));
  return true;
}

const std::vector<Suite>& Suites() { return Registry(); }

int RunGoogleBenchmarks(const std::string& prefix, const std::vector<std::string>& args,
                        benchmark::BenchmarkReporter* reporter) {
  std::vector<std::string> storage = {"spritestation-bench", "--benchmark_filter=^" + prefix};
  storage.insert(storage.end(), args.begin(), args.end());
  std::vector<char*> argv;
  argv.reserve(storage.size());
  for (auto& s : storage) argv.push_back(s.data());
  int argc = static_cast<int>(argv.size());
  benchmark::Initialize(&argc, argv.data());
  if (benchmark::ReportUnrecognizedArguments(argc, argv.data())) return 2;
  benchmark::RunSpecifiedBenchmarks(reporter);
  benchmark::Shutdown();
  return 0;
}

void RealTimes::ReportRuns(const std::vector<Run>& runs) {
  for (const Run& r : runs) {
    if (r.error_occurred || r.run_type != Run::RT_Iteration) continue;
    const std::string& args = r.run_name.args;
    time[r.run_name.function_name + (args.empty() ? "" : "/" + args)] = r.GetAdjustedRealTime();
  }
  ConsoleReporter::ReportRuns(runs);
}

}  // namespace ss::bench
