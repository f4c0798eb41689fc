// An animation's sequences file (animate/sequence_io.h): what `render` reads.
#include "animate/sequence_io.h"
#include "tests/fuzz/fuzz_support.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string path = ss::fuzz::WriteFile("walk.json", data, size);
  return ss::fuzz::Expect([&] { ss::ReadSequenceFile(path); });
}
