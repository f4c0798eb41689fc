#pragma once
// Reading a whole input file that a parser takes in one piece (a config, an animation spec),
// with a limit on its size checked before the parser sees it.
#include <cstdint>
#include <istream>
#include <string>

namespace ss {

// What a config file or an animation spec may weigh: yaml-cpp builds the whole document before
// it is read (~1.5 KB a node; a 250 MB config took seconds and GBs), and real ones are a few KB.
inline constexpr uintmax_t kMaxInputFileBytes = uintmax_t{16} << 20;  // 16 MiB

// Everything `in` (opened on `path`) holds. Throws InputError naming the file, its size and the
// limit when it holds more than `max_bytes` ("station.yaml: 250.0 MiB (262144000 bytes): larger
// than the 16 MiB a config file may be"): from its size before reading a byte, or, for what has
// no size (a pipe, a device), once more than the limit has been read. `what`: "a config file".
std::string ReadWithinLimit(std::istream& in, const std::string& path, const std::string& what,
                            uintmax_t max_bytes = kMaxInputFileBytes);

}  // namespace ss
