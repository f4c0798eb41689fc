// A recorded session's session.json (core/session.h), read from its folder.
#include "core/session.h"
#include "tests/fuzz/fuzz_support.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  ss::fuzz::WriteFile("session.json", data, size);
  return ss::fuzz::Expect([&] { ss::ReadSessionInfo(ss::fuzz::ScratchDir()); });
}
