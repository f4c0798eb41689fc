// A labels CSV of sprite pairs (pipeline/transitions/training.h): what `transitions train`
// reads, and what the labelling page exports.
#include "pipeline/transitions/training.h"
#include "tests/fuzz/fuzz_support.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string path = ss::fuzz::WriteFile("labels.csv", data, size);
  return ss::fuzz::Expect([&] {
    double rate = 0;
    ss::ReadLabelsCsv(path, &rate);
  });
}
