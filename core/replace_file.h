#pragma once
// Writing a file whole, so that a reader never sees half of it: the text goes to a temporary
// beside it, then takes its name. A path that names something other than a regular file (a
// device such as /dev/null, a FIFO) is written into instead: renaming over it would replace the
// device with a file.
#include <string>
#include <string_view>

namespace ss {

// Writes `contents` to `path` as above. `what` names the contents in errors ("the sequences"):
// WorkError(path, "cannot write the sequences: <reason>") when it cannot be written (a full disk,
// no permission, a directory); the temporary is removed and the old file left as it was.
void ReplaceFile(const std::string& path, std::string_view contents, const std::string& what);

}  // namespace ss
