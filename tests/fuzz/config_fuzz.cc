// The station config (config/station_config.h): YAML with every section, field and polygon.
#include "config/station_config.h"
#include "tests/fuzz/fuzz_support.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  return ss::fuzz::Expect([&] {
    ss::ConfigReport report;
    ss::ConfigOptions options;
    options.check_files = false;  // the paths it names need not exist
    ss::ParseStationConfig(ss::fuzz::Text(data, size), "fuzz.yaml", ss::fuzz::ScratchDir(), &report,
                           options);
  });
}
