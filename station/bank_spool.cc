#include "station/bank_spool.h"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>

#include <nlohmann/json.hpp>

#include "core/bank_pixels.h"
#include "core/error.h"
#include "core/log.h"
#include "core/posix.h"

namespace ss {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

constexpr const char* kFormat = "spritestation spool batch 1";

std::string Name(uint64_t n) {
  char buffer[32];
  std::snprintf(buffer, sizeof(buffer), "%012llu.batch", static_cast<unsigned long long>(n));
  return buffer;
}

void WriteAll(int fd, const std::vector<uint8_t>& bytes, const std::string& path) {
  size_t done = 0;
  while (done < bytes.size()) {
    const ssize_t n = ::write(fd, bytes.data() + done, bytes.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) throw WorkError(path, std::string("cannot write: ") + ErrnoText(errno));
    done += static_cast<size_t>(n);
  }
}

void SyncDir(const std::string& dir) {
  const int fd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY);
  if (fd >= 0) {
    ::fsync(fd);
    ::close(fd);
  }
}

}  // namespace

std::vector<uint8_t> BankSpool::Encode(const ClipBatch& batch) {
  PixelCodec codec;
  json sprites = json::array();
  for (const SpriteRecord& s : batch.sprites) {
    json j = {
        {"frame", s.frame},
        {"timestamp_ns", s.timestamp_ns},
        {"mirrored", s.mirrored},
        {"ground", {s.ground_x_m, s.ground_y_m}},
        {"velocity", {s.velocity_x_m_s, s.velocity_y_m_s}},
        {"mean_rgb", {s.mean_r, s.mean_g, s.mean_b}},
        {"area_px", s.area_px},
        {"eccentricity", s.eccentricity},
        {"bbox",
         {s.bbox_in_image.x, s.bbox_in_image.y, s.bbox_in_image.width, s.bbox_in_image.height}},
        {"billboard", {s.billboard_width_px, s.billboard_height_px}},
        {"px_per_m", s.px_per_m},
        {"anchor", {s.anchor_x_px, s.anchor_y_px}},
        {"kind", TextOf(s.kind, kSpriteKindTexts)},
        {"heading_rad", s.heading_rad},
        {"tags", s.tags}};
    if (!s.mirrored) j["pixels"] = json::binary(codec.Encode(s.pixels));
    sprites.push_back(std::move(j));
  }
  const ClipRecord& c = batch.clip;
  const json j = {{"format", kFormat},
                  {"clip",
                   {{"camera_id", c.camera_id},
                    {"track_id", c.track_id},
                    {"first_frame", c.first_frame},
                    {"last_frame", c.last_frame},
                    {"complete", c.complete}}},
                  {"sprites", std::move(sprites)}};
  return json::to_cbor(j);
}

ClipBatch BankSpool::Decode(const std::vector<uint8_t>& bytes, const std::string& what) {
  try {
    const json j = json::from_cbor(bytes);
    if (j.value("format", "") != kFormat) throw InputError(what, "not a spooled batch (format)");
    ClipBatch batch;
    const json& c = j.at("clip");
    batch.clip.camera_id = c.at("camera_id").get<int64_t>();
    batch.clip.track_id = c.at("track_id").get<int64_t>();
    batch.clip.first_frame = c.at("first_frame").get<int64_t>();
    batch.clip.last_frame = c.at("last_frame").get<int64_t>();
    batch.clip.complete = c.at("complete").get<bool>();
    PixelCodec codec;
    for (const json& s : j.at("sprites")) {
      SpriteRecord r;
      r.frame = s.at("frame").get<int64_t>();
      r.timestamp_ns = s.at("timestamp_ns").get<int64_t>();
      r.mirrored = s.at("mirrored").get<bool>();
      r.ground_x_m = s.at("ground").at(0).get<double>();
      r.ground_y_m = s.at("ground").at(1).get<double>();
      r.velocity_x_m_s = s.at("velocity").at(0).get<double>();
      r.velocity_y_m_s = s.at("velocity").at(1).get<double>();
      r.mean_r = s.at("mean_rgb").at(0).get<double>();
      r.mean_g = s.at("mean_rgb").at(1).get<double>();
      r.mean_b = s.at("mean_rgb").at(2).get<double>();
      r.area_px = s.at("area_px").get<double>();
      r.eccentricity = s.at("eccentricity").get<double>();
      const json& b = s.at("bbox");
      r.bbox_in_image =
          cv::Rect(b.at(0).get<int>(), b.at(1).get<int>(), b.at(2).get<int>(), b.at(3).get<int>());
      r.billboard_width_px = s.at("billboard").at(0).get<int>();
      r.billboard_height_px = s.at("billboard").at(1).get<int>();
      r.px_per_m = s.at("px_per_m").get<double>();
      r.anchor_x_px = s.at("anchor").at(0).get<double>();
      r.anchor_y_px = s.at("anchor").at(1).get<double>();
      // Spooled before floor sprites: upright.
      if (const std::string kind = s.value("kind", "upright");
          !FromText(kind, kSpriteKindTexts, r.kind)) {
        throw InputError(what, "unknown sprite kind '" + kind + "'");
      }
      r.heading_rad = s.value("heading_rad", 0.0);
      r.tags = s.at("tags").get<std::vector<std::string>>();
      if (!r.mirrored) {
        const auto& blob = s.at("pixels").get_binary();
        r.pixels = codec.Decode(blob.data(), blob.size(), r.billboard_width_px,
                                r.billboard_height_px, kPixelCodec);
      }
      batch.sprites.push_back(std::move(r));
    }
    return batch;
  } catch (const json::exception& e) {
    throw InputError(what, std::string("not a spooled batch (") + e.what() + ")");
  } catch (const WorkError& e) {
    throw InputError(what, std::string("damaged pixels: ") + e.what());
  }
}

BankSpool::BankSpool(std::string dir, int64_t max_bytes)
    : dir_(std::move(dir)), max_bytes_(max_bytes) {
  std::error_code ec;
  fs::create_directories(dir_, ec);
  if (ec || !fs::is_directory(dir_))
    throw WorkError(dir_, "cannot make the spool folder: " + ec.message());
  std::vector<std::string> names;
  for (const auto& entry : fs::directory_iterator(dir_, ec)) {
    const std::string name = entry.path().filename().string();
    if (entry.is_regular_file() && name.size() == 18 && name.substr(12) == ".batch")
      names.push_back(name);
    if (name.rfind(".writing-", 0) == 0)
      fs::remove(entry.path(), ec);  // a write cut short: never counted
  }
  std::sort(names.begin(), names.end());
  for (const std::string& name : names) {
    const std::string path = (fs::path(dir_) / name).string();
    const int64_t size = static_cast<int64_t>(fs::file_size(path, ec));
    files_.push_back({path, ec ? 0 : size});
    bytes_ += files_.back().bytes;
    next_ = std::max<uint64_t>(next_, std::strtoull(name.c_str(), nullptr, 10) + 1);
  }
  if (!files_.empty()) {
    Log("station")->info("spool {}: {} batches ({} bytes) from an earlier run wait for the bank",
                         dir_, files_.size(), bytes_);
  }
}

bool BankSpool::Push(const ClipBatch& batch) {
  const std::vector<uint8_t> bytes = Encode(batch);
  if (bytes_ + static_cast<int64_t>(bytes.size()) > max_bytes_) return false;
  const std::string name = Name(next_);
  const std::string path = (fs::path(dir_) / name).string();
  const std::string temp = (fs::path(dir_) / (".writing-" + name)).string();
  const int fd = ::open(temp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) throw WorkError(temp, std::string("cannot write: ") + ErrnoText(errno));
  try {
    WriteAll(fd, bytes, temp);
    if (::fsync(fd) != 0) throw WorkError(temp, std::string("cannot write: ") + ErrnoText(errno));
  } catch (...) {
    ::close(fd);
    ::unlink(temp.c_str());
    throw;
  }
  ::close(fd);
  if (::rename(temp.c_str(), path.c_str()) != 0) {
    ::unlink(temp.c_str());
    throw WorkError(path, std::string("cannot write: ") + ErrnoText(errno));
  }
  SyncDir(dir_);
  ++next_;
  files_.push_back({path, static_cast<int64_t>(bytes.size())});
  bytes_ += static_cast<int64_t>(bytes.size());
  return true;
}

std::optional<ClipBatch> BankSpool::Front() {
  while (!files_.empty()) {
    const File& f = files_.front();
    std::ifstream in(f.path, std::ios::binary);
    std::vector<uint8_t> bytes((std::istreambuf_iterator<char>(in)),
                               std::istreambuf_iterator<char>());
    try {
      if (!in && !in.eof()) throw InputError(f.path, "cannot read");
      return Decode(bytes, f.path);
    } catch (const InputError& e) {
      MoveToDamaged(e.what());
    }
  }
  return std::nullopt;
}

void BankSpool::SetAsideFront(const std::string& why) {
  if (!files_.empty()) MoveToDamaged(why);
}

void BankSpool::MoveToDamaged(const std::string& why) {
  const File& f = files_.front();
  const fs::path damaged = fs::path(dir_) / "damaged";
  std::error_code ec;
  fs::create_directories(damaged, ec);
  fs::rename(f.path, damaged / fs::path(f.path).filename(), ec);
  Log("station")->error("spool: {}: {} (moved to {})", f.path, why, damaged.string());
  bytes_ -= f.bytes;
  files_.erase(files_.begin());
}

void BankSpool::PopFront() {
  if (files_.empty()) return;
  std::error_code ec;
  fs::remove(files_.front().path, ec);
  bytes_ -= files_.front().bytes;
  files_.erase(files_.begin());
}

}  // namespace ss
