// A camera's frames.csv (core/session.h): one row per recorded frame.
#include "core/session.h"
#include "tests/fuzz/fuzz_support.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string path = ss::fuzz::WriteFile("cam0.frames.csv", data, size);
  return ss::fuzz::Expect([&] { ss::ReadFrameCsv(path); });
}
