#pragma once
// What a camera shows the console: a snapshot of its latest frame (taken by
// the pipeline thread a few times a second, read by any number of HTTP
// threads), the views drawn from it (raw, keyed), the sprites view's overlay
// (every candidate with its outline, contact point, track and verdict) and
// the exposure aid (how the green screen is lit). Everything past the
// snapshot's copy runs on the reader's thread, never on capture's.
#include <chrono>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <nlohmann/json_fwd.hpp>
#include <opencv2/core.hpp>

#include "pipeline/filter/usability.h"
#include "pipeline/run/camera_pipeline.h"

namespace ss {

struct PreviewCandidate {
  cv::Rect bbox;                          // camera pixels
  std::vector<cv::Point> outline;         // the silhouette's outer contour, camera pixels
  cv::Point2d contact;                    // the contact point, camera pixels
  int track = -1;                         // -1: its ray missed the floor
  std::optional<Eigen::Vector2d> ground;  // metres
  Discard reason = Discard::kNone;
  bool merged = false;  // two or more subjects in one blob: stored tagged `merged`
};

struct PreviewFrame {
  uint64_t sequence = 0;
  int64_t timestamp_ns = 0;
  std::chrono::steady_clock::time_point taken{};
  cv::Mat bgr;            // the whole frame
  cv::Mat alpha, shadow;  // its matte; empty before the keyer has learnt the enclosure
  bool training = false;  // the keyer is still learning: no candidates
  std::vector<PreviewCandidate> candidates;
};

// The candidates of the pipeline's last frame, with their outlines traced from their alpha.
std::vector<PreviewCandidate> PreviewCandidates(const std::vector<CandidateVerdict>& verdicts);

enum class PreviewView { kRaw, kKeyed };
// The view as a BGR image at most `max_width` wide (aspect kept). kKeyed: the subject over
// mid grey, the contact shadow darkening the grey; before the keyer learnt, the frame dimmed.
// A raw view that needs no scaling shares `frame.bgr`'s pixels: read it while `frame` lives.
cv::Mat RenderPreview(const PreviewFrame& frame, PreviewView view, int max_width);
std::vector<uint8_t> EncodeJpeg(const cv::Mat& bgr, int quality = 80);

// `verdict`: "stored" (usable while a session stores), "usable", or the discard reason.
// Coordinates stay camera pixels; `image_data_url` is the raw view it belongs to.
nlohmann::json SpritesViewJson(const PreviewFrame& frame, bool storing,
                               const std::string& image_data_url, double image_scale);
std::string Base64(const std::vector<uint8_t>& bytes);

// How the green screen is lit, from one frame (every 2nd pixel of every 2nd row).
// Green screen: green leads red and blue by 15 levels, and the matte (if any) says background.
struct ExposureFigures {
  bool measured = false;
  double green_fraction = 0;                                    // of the image
  std::vector<uint32_t> histogram_r, histogram_g, histogram_b;  // 32 bins over green-screen pixels
  double clipped_percent = 0;  // pixels of the whole image with a channel at 255
  double dark_percent = 0;     // green-screen pixels with green below 40
  // 1 - std/mean of the green level over 8x8 cells mostly green screen
  double green_uniformity = 0;
  double green_min_max = 0;  // darkest cell's green over the brightest's
};
ExposureFigures MeasureExposure(const PreviewFrame& frame);
nlohmann::json ExposureToJson(const ExposureFigures& e);

}  // namespace ss
