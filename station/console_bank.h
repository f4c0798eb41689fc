#pragma once
// The console's view of the sprite bank (`/api/bank/...`, docs/console.md):
// sessions, clips, a clip's sprites, one sprite with its transitions, its
// billboard as PNG, tags on a run of frames, and CSV export. Every call opens
// its own read-only connection (WAL: readers never block the station's
// writer); tagging opens a short-lived writer.
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json_fwd.hpp>

namespace ss {

class ConsoleBank {
 public:
  explicit ConsoleBank(std::string path) : path_(std::move(path)) {}

  nlohmann::json Sessions() const;
  // NotFoundError naming the session / clip / sprite when it is not in the bank (404).
  nlohmann::json Clips(int64_t session_id) const;
  nlohmann::json ClipSprites(int64_t clip_id) const;
  nlohmann::json Sprite(int64_t sprite_id) const;
  // PNG with alpha, scaled down to at most `max_height` pixels high (0: as stored).
  std::vector<uint8_t> BillboardPng(int64_t sprite_id, int max_height) const;
  // `body`: {"tag", "sprites": [ids]} or {"tag", "clip", "first_frame", "last_frame"} (a run of a
  // clip's frames, with their mirrored copies; api::ParseTag). InputError naming the field.
  // Returns the number of sprites (un)tagged.
  int64_t Tag(const nlohmann::json& body, bool remove) const;
  // The sprites of a clip, or with a tag, as `bank export`'s sprites.csv (originals and mirrors).
  std::string ExportCsv(std::optional<int64_t> clip_id, const std::string& tag) const;

 private:
  std::string path_;
};

}  // namespace ss
