#include "core/posix.h"

#include <sys/resource.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <cstdlib>
#include <cstring>

namespace ss {

std::string ErrnoText(int err) {
  char buffer[256];
  // GNU strerror_r: returns the text, in `buffer` or a static string of its own.
  return strerror_r(err, buffer, sizeof(buffer));
}

std::optional<std::string> Environment(const char* name) {
  // Read only, and never while another thread could write it (core/posix.h).
  const char* value = std::getenv(name);  // NOLINT(concurrency-mt-unsafe)
  if (value == nullptr) return std::nullopt;
  return std::string(value);
}

void SetThisThreadNice(int nice) {
  setpriority(PRIO_PROCESS, static_cast<id_t>(syscall(SYS_gettid)), nice);
}

}  // namespace ss
