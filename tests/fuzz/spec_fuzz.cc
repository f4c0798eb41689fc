// The animation spec (animate/spec.h): YAML with windows, counts and constraints.
#include "animate/spec.h"
#include "tests/fuzz/fuzz_support.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  return ss::fuzz::Expect([&] { ss::ParseAnimationSpec(ss::fuzz::Text(data, size), "fuzz.yaml"); });
}
