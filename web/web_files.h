#pragma once
// The console's pages as built into the executable (web/CMakeLists.txt). This
// library depends on nothing: the daemon hands its files to the HTTP server,
// which types them by extension.
#include <cstddef>  // size_t, in the generated source
#include <optional>
#include <string_view>

namespace ss {

// The bytes of `path` relative to web/, e.g. "index.html", "js/api.js"; nullopt when not embedded.
std::optional<std::string_view> FindEmbeddedWebFile(std::string_view path);

}  // namespace ss
