#pragma once
// Benchmark suites run as `spritestation bench NAME [args]`. Each bench/*_bench.cc
// registers one suite; the suite runs its Google Benchmark cases and prints its
// figures (ratios against a baseline measured in the same run).
#include <string>
#include <vector>

namespace ss::bench {

struct Suite {
  std::string name;      // "key", "bank", "replay", ...
  std::string summary;   // one line for `spritestation bench --help`
  int (*run)(const std::vector<std::string>& args);  // exit code
};

bool RegisterSuite(Suite suite);
const std::vector<Suite>& Suites();

// Runs the Google Benchmark cases whose name starts with `prefix`, passing `args`
// through (e.g. --benchmark_min_time=0.5). Returns the benchmark library's verdict.
int RunGoogleBenchmarks(const std::string& prefix, const std::vector<std::string>& args);

}  // namespace ss::bench
