#include "core/utc_time.h"

#include <ctime>

namespace ss {
namespace {

std::string UtcNow(const char* format) {
  const std::time_t now = std::time(nullptr);
  std::tm utc{};
  gmtime_r(&now, &utc);
  char text[32];
  std::strftime(text, sizeof(text), format, &utc);
  return text;
}

}  // namespace

std::string UtcNowIso() { return UtcNow("%Y-%m-%dT%H:%M:%SZ"); }

std::string UtcNowStamp() { return UtcNow("%Y%m%dT%H%M%SZ"); }

}  // namespace ss
