#pragma once
// The console's pages as built into the executable (web/CMakeLists.txt). This
// library depends on nothing: the daemon hands its files to the HTTP server.
#include <cstddef>
#include <optional>
#include <string_view>

namespace ss {

struct EmbeddedWebFile {
  std::string_view bytes;
  std::string_view content_type;
};

// `path` relative to web/, e.g. "index.html", "js/api.js"; nullopt when not embedded.
std::optional<EmbeddedWebFile> FindEmbeddedWebFile(std::string_view path);
size_t EmbeddedWebFileCount();

}  // namespace ss
