#include "core/input_file.h"

#include <array>
#include <cstdio>
#include <filesystem>
#include <system_error>

#include "core/error.h"

namespace ss {
namespace {

// "16 MiB", "238.4 MiB", "1000 bytes".
std::string Amount(uintmax_t bytes) {
  constexpr uintmax_t kMib = uintmax_t{1} << 20;
  char text[64];
  if (bytes < kMib) {
    std::snprintf(text, sizeof text, "%ju bytes", bytes);
  } else if (bytes % kMib == 0) {
    std::snprintf(text, sizeof text, "%ju MiB", bytes / kMib);
  } else {
    std::snprintf(text, sizeof text, "%.1f MiB", static_cast<double>(bytes) / kMib);
  }
  return text;
}

}  // namespace

std::string ReadWithinLimit(std::istream& in, const std::string& path, const std::string& what,
                            uintmax_t max_bytes) {
  const std::string limit = "larger than the " + Amount(max_bytes) + " " + what + " may be";
  std::error_code ec;
  // fails for what is not a regular file
  const uintmax_t size = std::filesystem::file_size(path, ec);
  if (!ec && size > max_bytes) {
    const std::string bytes = std::to_string(size) + " bytes";
    throw InputError(
        path, (Amount(size) == bytes ? bytes : Amount(size) + " (" + bytes + ")") + ": " + limit);
  }
  std::string text;
  if (!ec) text.reserve(size);
  std::array<char, 65536> buffer;
  while (in.read(buffer.data(), buffer.size()) || in.gcount() > 0) {
    text.append(buffer.data(), static_cast<size_t>(in.gcount()));
    if (text.size() > max_bytes)
      throw InputError(path, "more than " + Amount(max_bytes) + " read: " + limit);
  }
  return text;
}

}  // namespace ss
