#pragma once
// The records the sprite bank stores and returns (docs/formats.md has the schema).
// Ground frame: z up, z = 0 the floor, metres. Billboard: the perspective-corrected
// sprite image at a fixed metric scale, x right, y down, pixels.
#include <cstdint>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "core/enum_text.h"

namespace ss {

// How a sprite's pixels stand in the world: `upright`, a billboard on a vertical plane facing
// the camera that filmed it (seed 000 §2.1), its anchor the contact point at its bottom; or
// `floor`, seen from above and laid on the floor facing the image's top, its anchor its centre
// (pipeline/rectify/floor_rectifier.h, issue 38). Either kind's mirror is its image flipped
// left to right.
enum class SpriteKind { kUpright, kFloor };
inline constexpr EnumText<SpriteKind> kSpriteKindTexts[] = {{SpriteKind::kUpright, "upright"},
                                                            {SpriteKind::kFloor, "floor"}};

// One recorded (or live) session; `uid` is stable so re-ingesting it adds nothing.
struct SessionRecord {
  int64_t id = 0;   // assigned by the bank
  std::string uid;  // e.g. "<session name>@<created>"; unique in the bank
  std::string name;
  std::string created;  // ISO 8601, UTC
  std::string source;   // where it came from (session directory, station name)
};

struct CameraRecord {
  int64_t id = 0;           // assigned by the bank
  int64_t session_id = 0;   // assigned by the bank
  std::string name;         // "cam0"; unique within its session
  std::string cameramodel;  // the mrcal .cameramodel text (empty when uncalibrated)
  int width = 0;            // image size in pixels
  int height = 0;
};

// A clip: a run of consecutive usable frames of one tracked subject in one camera.
// Identified by (camera_id, track_id, first_frame); readers see only complete clips.
struct ClipRecord {
  int64_t id = 0;  // assigned by the bank
  int64_t camera_id = 0;
  int64_t track_id = 0;     // the tracker's subject id within the camera
  int64_t first_frame = 0;  // source frame indices, inclusive
  int64_t last_frame = 0;
  bool complete = false;     // set by the batch that ends the clip
  int64_t complete_seq = 0;  // order in which clips completed (1, 2, ...); 0 while incomplete
};

// A sprite's billboard pixels: 8-bit BGRA (OpenCV's channel order; alpha = matte)
// and the 8-bit contact-shadow layer, both billboard-sized.
struct SpritePixels {
  cv::Mat bgra;    // CV_8UC4
  cv::Mat shadow;  // CV_8UC1; empty means no shadow (stored as zeros)
};

// The tag of a sprite whose blob held two or more subjects (the pipeline's MergeDetector,
// docs/pipeline.md): stored with the sprite; transitions leave such sprites out by default.
inline constexpr const char* kMergedTag = "merged";

struct SpriteRecord {
  int64_t id = 0;            // assigned by the bank
  int64_t clip_id = 0;       // set by the bank from the batch's clip
  int64_t camera_id = 0;     // set by the bank from the clip
  int64_t track_id = 0;      // set by the bank from the clip
  int64_t frame = 0;         // source frame index in the camera's video
  int64_t timestamp_ns = 0;  // device timestamp of that frame
  bool mirrored = false;     // the horizontally mirrored copy of the original at the same frame
  int64_t mirror_of = 0;     // id of the original (mirrored sprites; set by the bank), else 0
  double ground_x_m = 0, ground_y_m = 0;          // ground contact point
  double velocity_x_m_s = 0, velocity_y_m_s = 0;  // ground velocity (mirrored for the copy)
  double mean_r = 0, mean_g = 0, mean_b = 0;      // mean colour under the matte, 0..255
  double area_px = 0;       // sum of alpha/255 over the billboard, billboard pixels
  double eccentricity = 0;  // from the matte's second moments, 0 (round) .. 1 (a line)
  cv::Rect bbox_in_image;   // the sprite's box in the source image, pixels
  int billboard_width_px = 0, billboard_height_px = 0;
  double px_per_m = 0;                      // billboard scale, the same for the whole bank
  double anchor_x_px = 0, anchor_y_px = 0;  // ground contact point in the billboard
  SpriteKind kind = SpriteKind::kUpright;
  double heading_rad = 0;  // floor sprites: the ground direction the subject faces (image up)
  std::vector<std::string> tags;
  // Required for originals (billboard-sized); a mirrored sprite stores none: its
  // pixels are its original's, flipped horizontally.
  SpritePixels pixels;
};

// What the transition search reads for every sprite: compact, no pixels.
// Bank::LoadFeatures returns them ordered by (clip_id, mirrored, frame).
struct SpriteFeatures {
  int64_t id = 0;
  int64_t clip_id = 0;
  int64_t frame = 0;
  int64_t timestamp_ns = 0;
  int64_t mirror_of = 0;  // 0 for originals
  int32_t prev = -1;  // index (in the returned vector) of the same clip's sprite at frame-1, same
                      // mirrored flag
  int32_t next = -1;  // ... at frame+1; -1 at the clip's ends
  bool mirrored = false;
  float ground_x_m = 0, ground_y_m = 0, velocity_x_m_s = 0, velocity_y_m_s = 0;
  float mean_r = 0, mean_g = 0, mean_b = 0, area_px = 0, eccentricity = 0;
  bool floor = false;     // SpriteKind::kFloor
  float heading_rad = 0;  // floor sprites: the direction the subject faces
};

// A transition i -> j: D(i,j) and the cost C(i->j) (seed 000 §3).
struct TransitionRecord {
  int64_t from_sprite = 0;
  int64_t to_sprite = 0;
  double d = 0;
  double cost = 0;
};

// A person's judgement of the transition from_sprite -> to_sprite (the labelling page):
// "yes" (smooth), "no", or "skip" (not judged; never asked again, never exported).
struct TransitionLabelRecord {
  int64_t from_sprite = 0;
  int64_t to_sprite = 0;
  std::string label;        // yes | no | skip
  std::string labelled_at;  // ISO 8601 UTC
  std::string source;       // who or what labelled it ("console", ...)
};

}  // namespace ss
