#include "core/session.h"

#include <charconv>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <set>
#include <sstream>
#include <system_error>
#include <type_traits>

#include <nlohmann/json.hpp>

#include "core/error.h"
#include "core/log.h"
#include "core/recording_codecs.h"
#include "core/replace_file.h"

namespace ss {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

constexpr const char* kCsvHeader = "index,timestamp_ns,sequence,drops_before";
constexpr int kMaxImageSide = 65536;

// Validates one JSON object's fields; every error names the file and the field path.
class Fields {
 public:
  Fields(const std::string& path, const json& object, std::string prefix)
      : path_(path), object_(object), prefix_(std::move(prefix)) {}

  const json& Get(const std::string& key) const {
    auto it = object_.find(key);
    if (it == object_.end()) Fail(key, "missing");
    return *it;
  }
  bool Has(const std::string& key) const { return object_.contains(key); }

  std::string String(const std::string& key) const {
    const json& v = Get(key);
    if (!v.is_string()) Fail(key, "expected a string");
    return v.get<std::string>();
  }
  std::string NonEmptyString(const std::string& key) const {
    std::string s = String(key);
    if (s.empty()) Fail(key, "expected a non-empty string");
    return s;
  }
  bool Bool(const std::string& key) const {
    const json& v = Get(key);
    if (!v.is_boolean()) Fail(key, "expected true or false");
    return v.get<bool>();
  }
  int PositiveInt(const std::string& key, int max) const {
    const json& v = Get(key);
    if (!v.is_number_integer()) Fail(key, "expected a positive integer");
    const int64_t i = v.get<int64_t>();
    if (i <= 0) Fail(key, "expected a positive integer");
    if (i > max)
      Fail(key, "expected at most " + std::to_string(max) + ", got " + std::to_string(i));
    return static_cast<int>(i);
  }
  double PositiveNumber(const std::string& key) const {
    const json& v = Get(key);
    if (!v.is_number()) Fail(key, "expected a positive number");
    const double d = v.get<double>();
    if (!std::isfinite(d) || d <= 0) Fail(key, "expected a positive number");
    return d;
  }
  // A path relative to the session folder that stays inside it.
  std::string RelativePath(const std::string& key, bool allow_empty) const {
    std::string s = String(key);
    if (s.empty()) {
      if (allow_empty) return s;
      Fail(key, "expected a file name");
    }
    const fs::path p(s);
    if (p.is_absolute())
      Fail(key, "expected a path relative to the session folder, got '" + s + "'");
    for (const auto& part : p) {
      if (part == "..") Fail(key, "path '" + s + "' leaves the session folder");
    }
    return s;
  }

  [[noreturn]] void Fail(const std::string& key, const std::string& reason) const {
    throw InputError(path_, "field '" + prefix_ + key + "': " + reason);
  }

 private:
  const std::string& path_;
  const json& object_;
  std::string prefix_;
};

bool IsSafeStem(const std::string& name) {
  if (name.empty() || name.front() == '.') return false;
  for (char c : name) {
    const bool ok = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') ||
                    c == '_' || c == '-' || c == '.';
    if (!ok) return false;
  }
  return true;
}

SessionCamera ParseCamera(const std::string& path, const json& j, size_t i) {
  const std::string prefix = "cameras[" + std::to_string(i) + "].";
  if (!j.is_object()) {
    throw InputError(path, "field 'cameras[" + std::to_string(i) + "]': expected an object");
  }
  Fields f(path, j, prefix);
  SessionCamera c;
  c.name = f.NonEmptyString("name");
  if (!IsSafeStem(c.name)) {
    f.Fail("name", "'" + c.name + "' is not a plain file stem (letters, digits, '_', '-', '.')");
  }
  c.video = f.RelativePath("video", false);
  c.frames_csv = f.RelativePath("frames_csv", false);
  c.model = f.Has("model") ? f.RelativePath("model", true) : std::string();
  c.width = f.PositiveInt("width", kMaxImageSide);
  c.height = f.PositiveInt("height", kMaxImageSide);
  const std::string format = f.String("pixel_format");
  const auto parsed = ParsePixelFormat(format);
  if (!parsed) {
    f.Fail("pixel_format",
           "unknown pixel format '" + format +
               "' (expected mono8, bayer_rg8, bayer_gr8, bayer_gb8, bayer_bg8, rgb8, "
               "bgr8, yuyv, nv12 or mjpeg)");
  }
  c.pixel_format = *parsed;
  c.codec = f.String("codec");
  if (FindRecordingCodec(c.codec) == nullptr) {
    f.Fail("codec", "unknown codec '" + c.codec + "' (expected " + RecordingCodecNames() + ")");
  }
  if (c.pixel_format == PixelFormat::kMJPEG && c.codec != "mjpeg") {
    f.Fail("codec", "an mjpeg camera is stored as codec 'mjpeg', got '" + c.codec + "'");
  }
  if ((c.pixel_format == PixelFormat::kYUYV || c.pixel_format == PixelFormat::kNV12) &&
      c.width % 2 != 0) {
    f.Fail("width", format + " needs an even width, got " + std::to_string(c.width));
  }
  if (c.pixel_format == PixelFormat::kNV12 && c.height % 2 != 0) {
    f.Fail("height", "nv12 needs an even height, got " + std::to_string(c.height));
  }
  c.fps = f.PositiveNumber("fps");
  if (f.Has("frames")) {
    const json& v = f.Get("frames");
    if (!v.is_number_integer() || v.get<int64_t>() < 0)
      f.Fail("frames", "expected a non-negative integer");
    c.frames = v.get<int64_t>();
  }
  return c;
}

json CameraToJson(const SessionCamera& c) {
  json j{{"name", c.name},
         {"video", c.video},
         {"frames_csv", c.frames_csv},
         {"model", c.model},
         {"width", c.width},
         {"height", c.height},
         {"pixel_format", PixelFormatName(c.pixel_format)},
         {"codec", c.codec},
         {"fps", c.fps}};
  if (c.frames >= 0) j["frames"] = c.frames;
  return j;
}

// Parses one CSV field as a base-10 integer of type T.
template <typename T>
T ParseField(const std::string& where, const std::string& field, const std::string& text) {
  T value{};
  const char* begin = text.data();
  const char* end = text.data() + text.size();
  const auto [ptr, ec] = std::from_chars(begin, end, value);
  if (text.empty() || ec != std::errc() || ptr != end) {
    const std::string expected = std::is_signed_v<T> ? "an integer" : "a non-negative integer";
    throw InputError(where, "field '" + field + "': expected " + expected + ", got '" + text + "'");
  }
  return value;
}

}  // namespace

SessionInfo ReadSessionInfo(const std::string& dir) {
  const std::string path = (fs::path(dir) / "session.json").string();
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    std::error_code ec;
    throw InputError(path, fs::exists(dir, ec) ? "cannot open (is this a recorded session?)"
                                               : "no such session folder");
  }
  std::stringstream text;
  text << in.rdbuf();
  json root;
  try {
    root = json::parse(text.str());
  } catch (const json::exception& e) {  // parse errors, and numbers out of range (tests/fuzz)
    throw InputError(path, std::string("not valid JSON: ") + e.what());
  }
  if (!root.is_object()) throw InputError(path, "expected a JSON object at the top level");

  Fields f(path, root, "");
  SessionInfo info;
  const json& version = f.Get("format_version");
  if (!version.is_number_integer()) f.Fail("format_version", "expected an integer");
  info.format_version = version.get<int>();
  if (info.format_version != kSessionFormatVersion) {
    f.Fail("format_version", "unsupported version " + std::to_string(info.format_version) +
                                 " (this build reads version " +
                                 std::to_string(kSessionFormatVersion) + ")");
  }
  info.name = f.String("name");
  info.created = f.String("created");
  info.synthetic = f.Bool("synthetic");
  const json& cameras = f.Get("cameras");
  if (!cameras.is_array()) f.Fail("cameras", "expected an array");
  std::set<std::string> names;
  std::set<std::string> files;
  for (size_t i = 0; i < cameras.size(); ++i) {
    SessionCamera c = ParseCamera(path, cameras[i], i);
    const std::string where = "cameras[" + std::to_string(i) + "].";
    if (!names.insert(c.name).second) {
      throw InputError(path, "field '" + where + "name': camera '" + c.name + "' appears twice");
    }
    for (const auto* file : {&c.video, &c.frames_csv, &c.model}) {
      if (file->empty()) continue;
      if (!files.insert(*file).second) {
        throw InputError(path, "field '" + where + "': file '" + *file + "' is used twice");
      }
    }
    info.cameras.push_back(std::move(c));
  }
  return info;
}

void WriteSessionInfo(const std::string& dir, const SessionInfo& info) {
  json cameras = json::array();
  for (const auto& c : info.cameras) cameras.push_back(CameraToJson(c));
  const json root{{"format_version", info.format_version},
                  {"name", info.name},
                  {"created", info.created},
                  {"synthetic", info.synthetic},
                  {"cameras", cameras}};
  ReplaceFile((fs::path(dir) / "session.json").string(), root.dump(2) + "\n", "the session");
}

std::vector<FrameRecord> ReadFrameCsv(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    std::error_code ec;
    throw InputError(path, fs::exists(path, ec) ? "cannot open" : "no such file");
  }
  std::stringstream buffer;
  buffer << in.rdbuf();
  const std::string text = buffer.str();
  if (text.empty())
    throw InputError(path,
                     "empty file, expected the header line '" + std::string(kCsvHeader) + "'");

  std::vector<FrameRecord> records;
  size_t pos = 0;
  int line_no = 0;
  while (pos < text.size()) {
    const size_t nl = text.find('\n', pos);
    const bool terminated = nl != std::string::npos;
    std::string line = text.substr(pos, terminated ? nl - pos : std::string::npos);
    pos = terminated ? nl + 1 : text.size();
    ++line_no;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    const std::string where = path + ":" + std::to_string(line_no);
    if (line_no == 1) {
      if (line != kCsvHeader) {
        throw InputError(where, "expected the header line '" + std::string(kCsvHeader) +
                                    "', got '" + line.substr(0, 80) + "'");
      }
      continue;
    }
    if (line.empty() && pos >= text.size()) break;  // trailing newline
    try {
      std::vector<std::string> fields;
      size_t start = 0;
      while (true) {
        const size_t comma = line.find(',', start);
        fields.push_back(
            line.substr(start, comma == std::string::npos ? std::string::npos : comma - start));
        if (comma == std::string::npos) break;
        start = comma + 1;
      }
      if (fields.size() != 4) {
        throw InputError(where, "expected 4 comma-separated fields (" + std::string(kCsvHeader) +
                                    "), got " + std::to_string(fields.size()));
      }
      FrameRecord r;
      r.index = ParseField<int64_t>(where, "index", fields[0]);
      r.timestamp_ns = ParseField<int64_t>(where, "timestamp_ns", fields[1]);
      r.sequence = ParseField<uint64_t>(where, "sequence", fields[2]);
      r.drops_before = ParseField<uint64_t>(where, "drops_before", fields[3]);
      const auto expected = static_cast<int64_t>(records.size());
      if (r.index != expected) {
        throw InputError(where, "field 'index': expected " + std::to_string(expected) +
                                    " (rows count up from 0), got " + std::to_string(r.index));
      }
      records.push_back(r);
    } catch (const InputError& e) {
      // A last row without its newline is a write torn by a killed recorder: drop it.
      if (!terminated) {
        Log("core.session")
            ->warn("{}: ignoring the unterminated last row (recording interrupted?)", where);
        break;
      }
      throw;
    }
  }
  return records;
}

FrameCsvWriter::FrameCsvWriter(const std::string& path) : path_(path) {
  out_.open(path, std::ios::binary | std::ios::trunc);
  if (!out_) throw WorkError(path, "cannot open for writing");
  out_ << kCsvHeader << '\n';
  out_.flush();
  if (!out_) throw WorkError(path, "write failed (disk full?)");
}

void FrameCsvWriter::Append(const FrameRecord& record) {
  if (!out_.is_open()) throw WorkError(path_, "append after close");
  // One formatted row, handed to the OS in one write so a kill cannot split it.
  char row[96];
  const int n = std::snprintf(
      row, sizeof(row), "%lld,%lld,%llu,%llu\n", static_cast<long long>(record.index),
      static_cast<long long>(record.timestamp_ns), static_cast<unsigned long long>(record.sequence),
      static_cast<unsigned long long>(record.drops_before));
  out_.write(row, n);
  out_.flush();
  if (!out_) throw WorkError(path_, "write failed (disk full?)");
}

void FrameCsvWriter::Close() {
  if (!out_.is_open()) return;
  out_.flush();
  out_.close();
}

}  // namespace ss
