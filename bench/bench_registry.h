#pragma once
// Benchmark suites run as `spritestation bench NAME [args]`. Each bench/*_bench.cc
// registers one suite; the suite runs its Google Benchmark cases and prints its
// figures (ratios against a baseline measured in the same run).
#include <map>
#include <string>
#include <utility>
#include <vector>

#include <benchmark/benchmark.h>

namespace ss::bench {

struct Suite {
  std::string name;                                  // "key", "bank", "replay", ...
  std::string summary;                               // one line for `spritestation bench --help`
  int (*run)(const std::vector<std::string>& args);  // exit code
};

bool RegisterSuite(Suite suite);

// "--name=value" as {"--name", "value"} ({"--name", ""} without '='): a suite's own options.
std::pair<std::string, std::string> OptionNameValue(const std::string& arg);
const std::vector<Suite>& Suites();

// Runs the Google Benchmark cases whose name starts with `prefix`, passing `args`
// through (e.g. --benchmark_min_time=0.5), reporting to `reporter` (the console when null).
// 2 for arguments the benchmark library does not know, else 0.
int RunGoogleBenchmarks(const std::string& prefix, const std::vector<std::string>& args,
                        benchmark::BenchmarkReporter* reporter = nullptr);

// The console table, and each case's real time in its unit by "name/args" (for the ratios a
// suite prints after the table).
class RealTimes : public benchmark::ConsoleReporter {
 public:
  void ReportRuns(const std::vector<Run>& runs) override;
  std::map<std::string, double> time;
};

}  // namespace ss::bench
