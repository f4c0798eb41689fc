#include "pipeline/transitions/bank_sprites.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstring>
#include <set>

#include "core/error.h"

namespace ss {

bool TableChoice::Takes(const SpriteRecord& sprite) const {
  return include_merged ||
         std::find(sprite.tags.begin(), sprite.tags.end(), kMergedTag) == sprite.tags.end();
}

TableChoice TableChoice::RecordedIn(const Bank& bank) {
  TableChoice choice;
  choice.include_merged = bank.GetMeta(kMetaKey).value_or("false") == "true";
  if (const auto cap = bank.GetMeta(kCapMetaKey)) {
    int value = 0;
    const auto [end, error] = std::from_chars(cap->data(), cap->data() + cap->size(), value);
    if (error == std::errc() && end == cap->data() + cap->size() && value >= 0)
      choice.max_per_sprite = value;
  }
  return choice;
}

CheapFeatures CheapFromRecord(const SpriteRecord& s) {
  CheapFeatures f;
  f.velocity_x_mps = s.velocity_x_m_s;
  f.velocity_y_mps = s.velocity_y_m_s;
  if (s.kind == SpriteKind::kFloor) {
    // A floor sprite may be turned about the vertical (the animator turns it at a transition):
    // its velocity is compared in its own axes, x ahead and y to its left, as its image is.
    const double c = std::cos(s.heading_rad), n = std::sin(s.heading_rad);
    f.velocity_x_mps = c * s.velocity_x_m_s + n * s.velocity_y_m_s;
    f.velocity_y_mps = -n * s.velocity_x_m_s + c * s.velocity_y_m_s;
  }
  f.colour[0] = s.mean_r;
  f.colour[1] = s.mean_g;
  f.colour[2] = s.mean_b;
  f.area_m2 = s.px_per_m > 0 ? s.area_px / (s.px_per_m * s.px_per_m) : 0.0;
  f.eccentricity = s.eccentricity;
  return f;
}

RgbaBillboard BillboardFromPixels(const SpritePixels& pixels, double anchor_x_px,
                                  double anchor_y_px, bool floor) {
  if (pixels.bgra.type() != CV_8UC4) throw WorkError("billboard", "bank pixels are not 8-bit BGRA");
  RgbaBillboard b;
  b.width = pixels.bgra.cols;
  b.height = pixels.bgra.rows;
  b.anchor_x_px = anchor_x_px;
  b.anchor_y_px = anchor_y_px;
  b.floor = floor;
  b.rgba.resize(static_cast<size_t>(b.width) * b.height * 4);
  const size_t row_bytes = static_cast<size_t>(b.width) * 4;
  for (int y = 0; y < b.height; ++y)
    std::memcpy(b.rgba.data() + y * row_bytes, pixels.bgra.ptr(y), row_bytes);
  return b;
}

int64_t SegmentKeys::Key(int64_t clip_id, bool mirrored, int64_t frame) {
  auto [it, inserted] = last_.try_emplace({clip_id, mirrored}, Last{0, 0});
  if (inserted || frame != it->second.frame + 1) it->second.key = next_key_++;
  it->second.frame = frame;
  return it->second.key;
}

namespace {

// Appends one sprite (record + pixels) to `out`; checks the bank-wide scale.
void AddSprite(const Bank& bank, const SpriteRecord& r, SegmentKeys* keys, BankSprites* out) {
  const std::string who = "sprite " + std::to_string(r.id);
  if (out->px_per_m == 0) out->px_per_m = r.px_per_m;
  if (r.px_per_m != out->px_per_m) {
    throw InputError(bank.path(), who + " has px_per_m " + std::to_string(r.px_per_m) +
                                      ", the others " + std::to_string(out->px_per_m) +
                                      ": one bank must use one billboard scale");
  }
  RgbaBillboard b = BillboardFromPixels(bank.LoadPixels(r.id), r.anchor_x_px, r.anchor_y_px,
                                        r.kind == SpriteKind::kFloor);
  out->ids.push_back(r.id);
  out->billboards.push_back(std::move(b));
  out->inputs.push_back(
      {r.id, keys->Key(r.clip_id, r.mirrored, r.frame), CheapFromRecord(r), nullptr});
}

void Link(BankSprites* out) {
  for (size_t k = 0; k < out->inputs.size(); ++k) out->inputs[k].billboard = &out->billboards[k];
}

}  // namespace

BankSprites LoadBankSprites(const Bank& bank, SegmentKeys* keys,
                            const std::function<void(size_t, size_t)>& progress,
                            const TableChoice& choice) {
  // ordered by (clip, mirrored, frame)
  const std::vector<SpriteFeatures> features = bank.LoadFeatures();
  BankSprites out;
  out.ids.reserve(features.size());
  out.inputs.reserve(features.size());
  out.billboards.reserve(features.size());
  std::set<int64_t> clips;
  for (size_t k = 0; k < features.size(); ++k) {
    const SpriteRecord r = bank.LoadSprite(features[k].id);  // with its tags
    if (choice.Takes(r)) {
      AddSprite(bank, r, keys, &out);
      clips.insert(features[k].clip_id);
    } else {
      out.left_out.push_back(r.id);
    }
    if (progress && (k % 512 == 511 || k + 1 == features.size())) progress(k + 1, features.size());
  }
  out.clips = static_cast<int64_t>(clips.size());
  Link(&out);
  return out;
}

BankSprites LoadBankSpritesById(const Bank& bank, std::span<const int64_t> ids, SegmentKeys* keys,
                                double px_per_m, const TableChoice* choice) {
  BankSprites out;
  out.px_per_m = px_per_m;
  out.ids.reserve(ids.size());
  out.inputs.reserve(ids.size());
  out.billboards.reserve(ids.size());
  std::set<int64_t> clips;
  for (int64_t id : ids) {
    const SpriteRecord r = bank.LoadSprite(id);  // InputError naming the bank for an unknown id
    if (choice && !choice->Takes(r)) {
      out.left_out.push_back(id);
      continue;
    }
    AddSprite(bank, r, keys, &out);
    clips.insert(r.clip_id);
  }
  out.clips = static_cast<int64_t>(clips.size());
  Link(&out);
  return out;
}

}  // namespace ss
