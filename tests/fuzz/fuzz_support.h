#pragma once
// What every fuzz target shares. A target feeds the bytes to one parser; the parser may
// refuse them only with the project's own errors (InputError, WorkError: a clear message
// naming the field). Anything else — another exception, a crash, a sanitizer report, a
// timeout or running out of memory — is a finding (libFuzzer stops and writes the input).
#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "core/error.h"

namespace ss::fuzz {

// The bytes as a string (parsers that take text).
inline std::string Text(const uint8_t* data, size_t size) {
  return std::string(reinterpret_cast<const char*>(data), size);
}

// A private scratch folder for targets whose parser reads files, made once per process.
inline const std::string& ScratchDir() {
  static const std::string dir = [] {
    std::string tmpl = "/tmp/ss-fuzz-XXXXXX";
    if (!mkdtemp(tmpl.data())) std::abort();
    return tmpl;
  }();
  return dir;
}

// Writes the bytes to ScratchDir()/name and returns the path.
inline std::string WriteFile(const std::string& name, const uint8_t* data, size_t size) {
  const std::string path = ScratchDir() + "/" + name;
  FILE* f = std::fopen(path.c_str(), "wb");
  if (!f) std::abort();
  if (size > 0 && std::fwrite(data, 1, size, f) != size) std::abort();
  std::fclose(f);
  return path;
}

// Runs `parse`; the project's own errors are an answer, not a finding.
template <typename F>
int Expect(F&& parse) {
  try {
    parse();
  } catch (const ss::InputError&) {
  } catch (const ss::WorkError&) {
  }
  return 0;
}

}  // namespace ss::fuzz
