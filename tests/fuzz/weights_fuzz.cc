// The transition classifier's weights file (pipeline/transitions/weights.h): JSON.
#include "pipeline/transitions/weights.h"
#include "tests/fuzz/fuzz_support.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  return ss::fuzz::Expect([&] { ss::ParseWeights(ss::fuzz::Text(data, size), "fuzz.json"); });
}
