#pragma once
// Renders one camera's view of the studio: the clean plate (floor, walls, room)
// computed once, then per frame the contact shadows, the calibration boards and
// the subjects, ray-cast per pixel through the camera's lens with 4x4
// supersampling at edges. Produces the noise-free composite plus the truth
// mattes; Sensor turns the composite into the bytes a camera would deliver.
#include <cstdint>
#include <vector>

#include <opencv2/core.hpp>

#include "core/frame.h"
#include "core/geometry.h"
#include "synth/board.h"
#include "synth/lens.h"
#include "synth/primitives.h"
#include "synth/scene.h"

namespace ss::synth {

struct BoardInstance {
  const BoardTexture* texture = nullptr;
  Rigid3 ground_from_board;
};

// Everything in view at one frame time.
struct FrameScene {
  std::vector<Primitive> primitives;  // all subjects, all time slices
  int subjects = 0;
  int slices = 1;                     // > 1: motion blur, subsample s sees slice SliceOf(s)
  std::vector<BoardInstance> boards;  // boards are drawn before (behind) subjects
};

// A crop of a full-frame 8-bit matte.
struct MatteLayer {
  int subject = -1;  // -1: the shadow matte
  cv::Rect box;      // in the image; empty when nothing is set
  cv::Mat values;    // CV_8U, box.size()
};

struct CameraImage {
  cv::Mat bgr;                        // CV_8UC3 noise-free composite
  std::vector<MatteLayer> alpha;      // one per subject (may be empty), index = subject
  MatteLayer shadow;                  // how much the floor/walls were darkened (255 = black)
  std::vector<double> visible_px;     // per subject: rendered coverage in pixels
  std::vector<double> unoccluded_px;  // per subject: coverage had nothing been in front
};

inline constexpr int kSubsamples = 16;  // 4 x 4 per pixel
int SliceOf(int subsample, int slices);

class CameraRenderer {
 public:
  CameraRenderer(const SynthCamera& camera, const Studio& studio);
  const SynthCamera& camera() const { return camera_; }
  const cv::Mat& clean_plate() const { return plate_; }  // CV_8UC3 with vignetting and gains
  // The unit ray through image point (x, y) (pixel centres at integers), ground frame.
  Eigen::Vector3f RayAt(float x, float y) const;
  // Background point seen through the centre of pixel (x, y).
  Eigen::Vector3f BackgroundPoint(int x, int y) const { return bg_point_[y * camera_.width + x]; }
  Surface BackgroundSurface(int x, int y) const {
    return static_cast<Surface>(bg_surface_[y * camera_.width + x]);
  }
  void Render(const FrameScene& scene, CameraImage* out) const;

 private:
  float BackgroundDepth(int x, int y, const float d[3]) const;
  void DrawShadows(const FrameScene& scene, CameraImage* out) const;
  void DrawBoards(const FrameScene& scene, CameraImage* out) const;
  void DrawSubjects(const FrameScene& scene, CameraImage* out) const;
  float Vignette(int x, int y) const { return vignette_[y * camera_.width + x]; }

  SynthCamera camera_;
  const Studio* studio_;
  Eigen::Vector3d eye_;
  Lighting lighting_;
  std::vector<float> corner_rays_;  // (W+1) x (H+1) x 3, unit, at pixel corners
  std::vector<Eigen::Vector3f> bg_point_;
  std::vector<uint8_t> bg_surface_;
  std::vector<int16_t> bg_quad_;        // quad seen at the pixel centre
  std::vector<uint8_t> bg_edge_;        // 1 where more than one quad is in (or next to) the pixel
  std::vector<float> quad_n_, quad_k_;  // per quad: normal, n.(origin - eye)
  std::vector<float> vignette_;
  cv::Mat plate_;
};

// The sensor: shot and read noise on the composite, then the pixel format.
class Sensor {
 public:
  // `noise` scales the noise (1 = a typical machine-vision sensor, 0 = none).
  Sensor(uint64_t seed, int camera, double noise);
  // Bytes of one frame in `format` (kBGR8, kRGB8, kBayerRG8 or kMono8).
  std::vector<uint8_t> Capture(const cv::Mat& bgr, PixelFormat format, uint64_t frame_index) const;

 private:
  uint64_t seed_;
  int camera_;
  std::vector<float> table_;  // standard normal samples
  float sigma_[256];          // noise sigma per intensity, in DN
};

}  // namespace ss::synth
