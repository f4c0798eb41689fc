#include "bench/bench_registry.h"

#include <benchmark/benchmark.h>

namespace ss::bench {

static std::vector<Suite>& Registry() {
  static std::vector<Suite> suites;
  return suites;
}

bool RegisterSuite(Suite suite) {
  Registry().push_back(std::move(suite));
  return true;
}

const std::vector<Suite>& Suites() { return Registry(); }

int RunGoogleBenchmarks(const std::string& prefix, const std::vector<std::string>& args) {
  std::vector<std::string> storage = {"spritestation-bench", "--benchmark_filter=^" + prefix};
  storage.insert(storage.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (auto& s : storage) argv.push_back(s.data());
  int argc = static_cast<int>(argv.size());
  benchmark::Initialize(&argc, argv.data());
  if (benchmark::ReportUnrecognizedArguments(argc, argv.data())) return 2;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}

}  // namespace ss::bench
