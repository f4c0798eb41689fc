#include "core/bank_export.h"

#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <system_error>

#include <opencv2/imgcodecs.hpp>

#include "core/error.h"

namespace ss {

std::string SpriteCsvHeader() {
  return "id,clip_id,camera_id,track_id,frame,timestamp_ns,mirrored,mirror_of,ground_x_m,ground_y_"
         "m,"
         "velocity_x_m_s,velocity_y_m_s,mean_r,mean_g,mean_b,area_px,eccentricity,bbox_x,bbox_y,"
         "bbox_w,bbox_h,"
         "billboard_w_px,billboard_h_px,px_per_m,anchor_x_px,anchor_y_px,tags,png,shadow_png,kind,"
         "heading_rad\n";
}

std::string SpriteCsvRow(const SpriteRecord& s) {
  std::ostringstream csv;
  csv.precision(17);
  const std::string png = "sprite_" + std::to_string(s.id) + ".png";
  const std::string shadow_png = "sprite_" + std::to_string(s.id) + "_shadow.png";
  std::string tags;
  for (const auto& t : s.tags) tags += (tags.empty() ? "" : ";") + t;
  for (size_t q = tags.find('"'); q != std::string::npos; q = tags.find('"', q + 2))
    tags.insert(q, 1, '"');
  csv << s.id << ',' << s.clip_id << ',' << s.camera_id << ',' << s.track_id << ',' << s.frame
      << ',' << s.timestamp_ns << ',' << int{s.mirrored} << ',' << s.mirror_of << ','
      << s.ground_x_m << ',' << s.ground_y_m << ',' << s.velocity_x_m_s << ',' << s.velocity_y_m_s
      << ',' << s.mean_r << ',' << s.mean_g << ',' << s.mean_b << ',' << s.area_px << ','
      << s.eccentricity << ',' << s.bbox_in_image.x << ',' << s.bbox_in_image.y << ','
      << s.bbox_in_image.width << ',' << s.bbox_in_image.height << ',' << s.billboard_width_px
      << ',' << s.billboard_height_px << ',' << s.px_per_m << ',' << s.anchor_x_px << ','
      << s.anchor_y_px << ",\"" << tags << "\"," << png << ',' << shadow_png << ','
      << TextOf(s.kind, kSpriteKindTexts) << ',' << s.heading_rad << '\n';
  return csv.str();
}

int64_t ExportBank(const Bank& bank, const std::string& dir, const BankExportOptions& options) {
  namespace fs = std::filesystem;
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec) throw WorkError(dir, "cannot create the output folder (" + ec.message() + ")");
  const std::string csv_path = (fs::path(dir) / "sprites.csv").string();
  std::ofstream csv(csv_path);
  if (!csv) throw WorkError(csv_path, "cannot write");
  csv << SpriteCsvHeader();

  std::set<int64_t> tagged;
  if (!options.tag.empty()) {
    for (int64_t id : bank.SpritesTagged(options.tag)) tagged.insert(id);
  }
  int64_t written = 0;
  for (const SpriteFeatures& f : bank.LoadFeatures()) {
    if (f.mirrored && !options.include_mirrors) continue;
    if (!options.tag.empty() && !tagged.count(f.id)) continue;
    const SpriteRecord s = bank.LoadSprite(f.id);
    const SpritePixels pixels = bank.LoadPixels(f.id);
    const std::string png = "sprite_" + std::to_string(s.id) + ".png";
    const std::string shadow_png = "sprite_" + std::to_string(s.id) + "_shadow.png";
    if (!cv::imwrite((fs::path(dir) / png).string(), pixels.bgra))
      throw WorkError((fs::path(dir) / png).string(), "cannot write");
    if (!cv::imwrite((fs::path(dir) / shadow_png).string(), pixels.shadow)) {
      throw WorkError((fs::path(dir) / shadow_png).string(), "cannot write");
    }
    csv << SpriteCsvRow(s);
    ++written;
  }
  csv.flush();
  if (!csv) throw WorkError(csv_path, "cannot write");
  return written;
}

}  // namespace ss
