#include "station/preview.h"

#include <algorithm>
#include <cmath>

#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

namespace ss {

std::vector<PreviewCandidate> PreviewCandidates(const std::vector<CandidateVerdict>& verdicts) {
  std::vector<PreviewCandidate> out;
  out.reserve(verdicts.size());
  std::vector<std::vector<cv::Point>> contours;
  cv::Mat mask;
  for (const CandidateVerdict& v : verdicts) {
    if (v.candidate == nullptr) continue;
    const Candidate& c = *v.candidate;
    PreviewCandidate p{.bbox = c.bbox,
                       .contact = c.contact_point,
                       .track = v.track,
                       .ground = v.ground,
                       .reason = v.reason,
                       .merged = v.merged};
    if (!c.alpha.empty()) {
      cv::compare(c.alpha, 127, mask, cv::CMP_GT);
      contours.clear();
      cv::findContours(mask, contours, cv::RETR_EXTERNAL, cv::CHAIN_APPROX_SIMPLE, c.bbox.tl());
      const auto largest = std::max_element(
          contours.begin(), contours.end(),
          [](const auto& a, const auto& b) { return cv::contourArea(a) < cv::contourArea(b); });
      if (largest != contours.end()) cv::approxPolyDP(*largest, p.outline, 1.0, true);
    }
    out.push_back(std::move(p));
  }
  return out;
}

cv::Mat RenderPreview(const PreviewFrame& frame, PreviewView view, int max_width) {
  cv::Mat image;
  const bool keyed =
      view == PreviewView::kKeyed && !frame.alpha.empty() && frame.alpha.size() == frame.bgr.size();
  if (!keyed) {
    image = frame.bgr;
  } else {
    image.create(frame.bgr.size(), CV_8UC3);
    for (int y = 0; y < image.rows; ++y) {
      const cv::Vec3b* src = frame.bgr.ptr<cv::Vec3b>(y);
      const uint8_t* a = frame.alpha.ptr<uint8_t>(y);
      const uint8_t* sh = frame.shadow.empty() ? nullptr : frame.shadow.ptr<uint8_t>(y);
      cv::Vec3b* dst = image.ptr<cv::Vec3b>(y);
      for (int x = 0; x < image.cols; ++x) {
        const int grey = 128 * (255 - (sh ? sh[x] : 0)) / 255;
        for (int c = 0; c < 3; ++c)
          dst[x][c] = static_cast<uint8_t>((src[x][c] * a[x] + grey * (255 - a[x])) / 255);
      }
    }
  }
  // Not keyed yet (learning the enclosure): say so by showing it dimmed.
  const bool dim = view == PreviewView::kKeyed && !keyed;
  cv::Mat out;
  if (max_width > 0 && image.cols > max_width) {
    const int height =
        std::max(1, static_cast<int>(std::lround(double(image.rows) * max_width / image.cols)));
    cv::resize(image, out, cv::Size(max_width, height), 0, 0, cv::INTER_AREA);
  } else {
    out = dim ? image.clone() : image;  // a raw view at full size is the snapshot itself
  }
  if (dim) out *= 0.35;
  return out;
}

std::vector<uint8_t> EncodeJpeg(const cv::Mat& bgr, int quality) {
  std::vector<uint8_t> jpeg;
  cv::imencode(".jpg", bgr, jpeg, {cv::IMWRITE_JPEG_QUALITY, quality});
  return jpeg;
}

std::string Base64(const std::vector<uint8_t>& bytes) {
  static constexpr char kTable[] =
      "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  out.reserve((bytes.size() + 2) / 3 * 4);
  size_t i = 0;
  for (; i + 2 < bytes.size(); i += 3) {
    const uint32_t v = (uint32_t(bytes[i]) << 16) | (uint32_t(bytes[i + 1]) << 8) | bytes[i + 2];
    out += kTable[v >> 18];
    out += kTable[(v >> 12) & 63];
    out += kTable[(v >> 6) & 63];
    out += kTable[v & 63];
  }
  if (i + 1 == bytes.size()) {
    const uint32_t v = uint32_t(bytes[i]) << 16;
    out += kTable[v >> 18];
    out += kTable[(v >> 12) & 63];
    out += "==";
  } else if (i + 2 == bytes.size()) {
    const uint32_t v = (uint32_t(bytes[i]) << 16) | (uint32_t(bytes[i + 1]) << 8);
    out += kTable[v >> 18];
    out += kTable[(v >> 12) & 63];
    out += kTable[(v >> 6) & 63];
    out += '=';
  }
  return out;
}

nlohmann::json SpritesViewJson(const PreviewFrame& frame, bool storing,
                               const std::string& image_data_url, double image_scale) {
  nlohmann::json candidates = nlohmann::json::array();
  for (const PreviewCandidate& c : frame.candidates) {
    nlohmann::json outline = nlohmann::json::array();
    for (const cv::Point& p : c.outline) outline.push_back({p.x, p.y});
    const char* verdict = c.reason != Discard::kNone ? DiscardName(c.reason)
                          : storing                  ? "stored"
                                                     : "usable";
    candidates.push_back(
        {{"bbox", {c.bbox.x, c.bbox.y, c.bbox.width, c.bbox.height}},
         {"outline", outline},
         {"contact", {c.contact.x, c.contact.y}},
         {"track", c.track},
         {"verdict", verdict},
         {"merged", c.merged},
         {"ground", c.ground ? nlohmann::json{c.ground->x(), c.ground->y()} : nlohmann::json()}});
  }
  return {{"sequence", frame.sequence}, {"timestamp_ns", frame.timestamp_ns},
          {"width", frame.bgr.cols},    {"height", frame.bgr.rows},
          {"training", frame.training}, {"image", image_data_url},
          {"scale", image_scale},       {"candidates", candidates}};
}

ExposureFigures MeasureExposure(const PreviewFrame& frame) {
  ExposureFigures e;
  if (frame.bgr.empty() || frame.bgr.type() != CV_8UC3) return e;
  constexpr int kBins = 32, kCells = 8, kStep = 2;
  e.measured = true;
  e.histogram_r.assign(kBins, 0);
  e.histogram_g.assign(kBins, 0);
  e.histogram_b.assign(kBins, 0);
  const bool matte = !frame.alpha.empty() && frame.alpha.size() == frame.bgr.size();
  std::vector<double> cell_sum(kCells * kCells, 0), cell_green(kCells * kCells, 0),
      cell_all(kCells * kCells, 0);
  uint64_t all = 0, green = 0, clipped = 0, dark = 0;
  for (int y = 0; y < frame.bgr.rows; y += kStep) {
    const cv::Vec3b* row = frame.bgr.ptr<cv::Vec3b>(y);
    const uint8_t* a = matte ? frame.alpha.ptr<uint8_t>(y) : nullptr;
    const int cy = y * kCells / frame.bgr.rows;
    for (int x = 0; x < frame.bgr.cols; x += kStep) {
      const int b = row[x][0], g = row[x][1], r = row[x][2];
      const int cell = cy * kCells + x * kCells / frame.bgr.cols;
      ++all;
      ++cell_all[cell];
      if (b == 255 || g == 255 || r == 255) ++clipped;
      if (!(g > r + 15 && g > b + 15) || (a != nullptr && a[x] >= 16)) continue;
      ++green;
      ++e.histogram_r[r * kBins / 256];
      ++e.histogram_g[g * kBins / 256];
      ++e.histogram_b[b * kBins / 256];
      if (g < 40) ++dark;
      cell_sum[cell] += g;
      ++cell_green[cell];
    }
  }
  e.green_fraction = all ? double(green) / all : 0;
  e.clipped_percent = all ? 100.0 * clipped / all : 0;
  e.dark_percent = green ? 100.0 * dark / green : 0;
  std::vector<double> levels;
  for (int k = 0; k < kCells * kCells; ++k) {
    if (cell_all[k] > 0 && cell_green[k] >= 0.5 * cell_all[k])
      levels.push_back(cell_sum[k] / cell_green[k]);
  }
  if (!levels.empty()) {
    double mean = 0;
    for (const double l : levels) mean += l;
    mean /= levels.size();
    double var = 0;
    for (const double l : levels) var += (l - mean) * (l - mean);
    const double sd = std::sqrt(var / levels.size());
    e.green_uniformity = mean > 0 ? std::max(0.0, 1.0 - sd / mean) : 0;
    const auto [lo, hi] = std::minmax_element(levels.begin(), levels.end());
    e.green_min_max = *hi > 0 ? *lo / *hi : 0;
  }
  return e;
}

nlohmann::json ExposureToJson(const ExposureFigures& e) {
  if (!e.measured) return nlohmann::json::object();
  return {{"green_fraction", e.green_fraction},
          {"histogram", {{"r", e.histogram_r}, {"g", e.histogram_g}, {"b", e.histogram_b}}},
          {"clipped_percent", e.clipped_percent},
          {"dark_percent", e.dark_percent},
          {"green_uniformity", e.green_uniformity},
          {"green_min_max", e.green_min_max}};
}

}  // namespace ss
