#include "station/console_bank.h"

#include <algorithm>
#include <map>

#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "core/bank.h"
#include "core/bank_export.h"
#include "core/error.h"
#include "core/error_kinds.h"
#include "station/request_bodies.h"

namespace ss {
namespace {

constexpr size_t kMaxTransitionsShown = 50;

nlohmann::json Transitions(std::vector<TransitionRecord> list, bool outgoing) {
  std::sort(list.begin(), list.end(), [](const auto& a, const auto& b) { return a.cost < b.cost; });
  nlohmann::json out = nlohmann::json::array();
  for (size_t k = 0; k < list.size() && k < kMaxTransitionsShown; ++k) {
    out.push_back({{"sprite", outgoing ? list[k].to_sprite : list[k].from_sprite},
                   {"cost", list[k].cost},
                   {"d", list[k].d}});
  }
  return out;
}

}  // namespace

nlohmann::json ConsoleBank::Sessions() const {
  const Bank bank(path_);
  std::map<int64_t, nlohmann::json> by_id;
  nlohmann::json out = nlohmann::json::array();
  for (const SessionRecord& s : bank.ListSessions()) {
    by_id[s.id] = {{"id", s.id},
                   {"name", s.name},
                   {"created", s.created},
                   {"source", s.source},
                   {"cameras", nlohmann::json::array()},
                   {"clips", 0},
                   {"sprites", 0}};
  }
  std::map<int64_t, int64_t> session_of_camera;
  for (const CameraRecord& c : bank.ListCameras()) {
    session_of_camera[c.id] = c.session_id;
    auto it = by_id.find(c.session_id);
    if (it != by_id.end()) {
      it->second["cameras"].push_back(
          {{"id", c.id}, {"name", c.name}, {"width", c.width}, {"height", c.height}});
    }
  }
  const std::map<int64_t, int64_t> counts = bank.CountClipSprites();
  for (const ClipRecord& clip : bank.ListClips()) {
    auto it = by_id.find(session_of_camera[clip.camera_id]);
    if (it == by_id.end()) continue;
    it->second["clips"] = it->second["clips"].get<int64_t>() + 1;
    const auto n = counts.find(clip.id);
    it->second["sprites"] =
        it->second["sprites"].get<int64_t>() + (n == counts.end() ? 0 : n->second);
  }
  for (auto& [id, s] : by_id) out.push_back(std::move(s));
  return out;
}

nlohmann::json ConsoleBank::Clips(int64_t session_id) const {
  const Bank bank(path_);
  bool found = false;
  for (const SessionRecord& s : bank.ListSessions()) found = found || s.id == session_id;
  if (!found)
    throw NotFoundError("session",
                        "no session with id " + std::to_string(session_id) + " in the bank");
  std::map<int64_t, std::string> cameras;
  for (const CameraRecord& c : bank.ListCameras()) {
    if (c.session_id == session_id) cameras[c.id] = c.name;
  }
  const std::map<int64_t, int64_t> counts = bank.CountClipSprites();
  const auto tags = bank.CountClipTags();
  nlohmann::json out = nlohmann::json::array();
  for (const ClipRecord& clip : bank.ListClips()) {
    const auto camera = cameras.find(clip.camera_id);
    if (camera == cameras.end()) continue;
    const auto n = counts.find(clip.id);
    const auto t = tags.find(clip.id);
    out.push_back(
        {{"id", clip.id},
         {"camera", camera->second},
         {"camera_id", clip.camera_id},
         {"track_id", clip.track_id},
         {"first_frame", clip.first_frame},
         {"last_frame", clip.last_frame},
         {"sprites", n == counts.end() ? 0 : n->second},
         {"tags", t == tags.end() ? nlohmann::json::object() : nlohmann::json(t->second)}});
  }
  return out;
}

nlohmann::json ConsoleBank::ClipSprites(int64_t clip_id) const {
  const Bank bank(path_);
  const std::vector<ClipRecord> clips = bank.ListClips();
  if (std::none_of(clips.begin(), clips.end(),
                   [&](const ClipRecord& c) { return c.id == clip_id; })) {
    throw NotFoundError("clip",
                        "no complete clip with id " + std::to_string(clip_id) + " in the bank");
  }
  nlohmann::json out = nlohmann::json::array();
  for (const SpriteRecord& s : bank.LoadClipSprites(clip_id)) {
    out.push_back({{"id", s.id},
                   {"frame", s.frame},
                   {"timestamp_ns", s.timestamp_ns},
                   {"ground", {s.ground_x_m, s.ground_y_m}},
                   {"tags", s.tags}});
  }
  return out;
}

nlohmann::json ConsoleBank::Sprite(int64_t sprite_id) const {
  const Bank bank(path_);
  SpriteRecord s;
  try {
    s = bank.LoadSprite(sprite_id);
  } catch (const InputError&) {
    throw NotFoundError("sprite",
                        "no sprite with id " + std::to_string(sprite_id) + " in the bank");
  }
  std::string camera, session;
  int64_t session_id = 0;
  for (const CameraRecord& c : bank.ListCameras()) {
    if (c.id == s.camera_id) {
      camera = c.name;
      session_id = c.session_id;
    }
  }
  for (const SessionRecord& r : bank.ListSessions()) {
    if (r.id == session_id) session = r.name;
  }
  const double area_m2 = s.px_per_m > 0 ? s.area_px / (s.px_per_m * s.px_per_m) : 0;
  return {{"id", s.id},
          {"camera", camera},
          {"camera_id", s.camera_id},
          {"session", session},
          {"session_id", session_id},
          {"clip_id", s.clip_id},
          {"track_id", s.track_id},
          {"frame", s.frame},
          {"timestamp_ns", s.timestamp_ns},
          {"mirrored", s.mirrored},
          {"mirror_of", s.mirror_of},
          {"ground", {s.ground_x_m, s.ground_y_m}},
          {"velocity", {s.velocity_x_m_s, s.velocity_y_m_s}},
          {"features",
           {{"velocity_m_s", {s.velocity_x_m_s, s.velocity_y_m_s}},
            {"mean_colour", {s.mean_r, s.mean_g, s.mean_b}},
            {"area_px", s.area_px},
            {"area_m2", area_m2},
            {"eccentricity", s.eccentricity}}},
          {"bbox_in_image",
           {s.bbox_in_image.x, s.bbox_in_image.y, s.bbox_in_image.width, s.bbox_in_image.height}},
          {"billboard",
           {{"width", s.billboard_width_px},
            {"height", s.billboard_height_px},
            {"px_per_m", s.px_per_m},
            {"anchor", {s.anchor_x_px, s.anchor_y_px}}}},
          {"kind", TextOf(s.kind, kSpriteKindTexts)},
          {"heading_rad", s.heading_rad},
          {"tags", s.tags},
          {"transitions_out", Transitions(bank.LoadTransitionsFrom(sprite_id), true)},
          {"transitions_in", Transitions(bank.LoadTransitionsTo(sprite_id), false)}};
}

std::vector<uint8_t> ConsoleBank::BillboardPng(int64_t sprite_id, int max_height) const {
  const Bank bank(path_);
  SpritePixels pixels;
  try {
    pixels = bank.LoadPixels(sprite_id);
  } catch (const InputError&) {
    throw NotFoundError("sprite",
                        "no sprite with id " + std::to_string(sprite_id) + " in the bank");
  }
  cv::Mat image = pixels.bgra;
  if (max_height > 0 && image.rows > max_height) {
    const int width = std::max(1, image.cols * max_height / image.rows);
    cv::resize(pixels.bgra, image, cv::Size(width, max_height), 0, 0, cv::INTER_AREA);
  }
  std::vector<uint8_t> png;
  cv::imencode(".png", image, png);
  return png;
}

int64_t ConsoleBank::Tag(const nlohmann::json& body, bool remove) const {
  const api::TagRequest r = api::ParseTag(body);
  std::vector<int64_t> ids = r.sprites;
  {
    const Bank bank(path_);
    if (ids.empty()) {
      ids = bank.ClipSpriteIds(r.clip, r.first_frame, r.last_frame);
      if (ids.empty()) {
        throw InputError("clip", "clip " + std::to_string(r.clip) + " has no sprites at frames " +
                                     std::to_string(r.first_frame) + ".." +
                                     std::to_string(r.last_frame));
      }
    }
  }
  const std::string& tag = r.tag;
  BankWriter writer(path_);
  try {
    if (remove) {
      writer.Untag(ids, tag);
    } else {
      writer.Tag(ids, tag);
    }
  } catch (const InputError& e) {
    throw InputError("sprites", e.what());
  }
  return static_cast<int64_t>(ids.size());
}

std::string ConsoleBank::ExportCsv(std::optional<int64_t> clip_id, const std::string& tag) const {
  const Bank bank(path_);
  std::vector<int64_t> ids;
  if (clip_id) {
    ids = bank.ClipSpriteIds(*clip_id, INT64_MIN, INT64_MAX);
    if (ids.empty())
      throw NotFoundError(
          "clip", "no clip with id " + std::to_string(*clip_id) + " and sprites in the bank");
  } else {
    ids = bank.SpritesTagged(tag);
  }
  std::string csv = SpriteCsvHeader();
  for (const int64_t id : ids) csv += SpriteCsvRow(bank.LoadSprite(id));
  return csv;
}

}  // namespace ss
