#pragma once
// Renders a whole synthetic studio session: the recorded-session format
// (capture/recording/session_writer.h: session.json, per camera an FFV1 video,
// a frame CSV and the true .cameramodel) plus truth/ (docs/synth.md):
//   truth/truth.json                 what the session holds, file patterns, options
//   truth/floor.json                 the floor polygon and walls, ground frame
//   truth/<cam>.cameramodel          the true camera models
//   truth/subjects.csv               per frame and subject: position, heading, speed, gait, pose,
//   ... truth/<cam>/views.csv            per frame, camera and subject: coverage, box, lowest point
//   truth/<cam>/overlaps.csv         (several subjects) per frame and pair: silhouettes touching
//   truth/<cam>/alpha_s<K>/<F>.png   per frame: subject K's alpha matte (8-bit, lossless)
//   truth/<cam>/shadow/<F>.png       per frame: the contact-shadow matte (255 = black)
//   (figure) truth/joints.csv, truth/<cam>/joints.csv; (calibration) truth/boards.json,
//   truth/board_poses.csv, truth/<cam>/corners.csv
#include <cstdint>
#include <map>
#include <optional>
#include <string>

#include "core/enum_text.h"
#include "core/frame.h"
#include "synth/directors.h"
#include "synth/scene.h"

namespace ss::synth {

enum class SynthKind { kAnimal, kFigure, kCalibration, kFly };
inline constexpr EnumText<SynthKind> kSynthKindTexts[] = {{SynthKind::kAnimal, "animal"},
                                                          {SynthKind::kFigure, "figure"},
                                                          {SynthKind::kCalibration, "calibration"},
                                                          {SynthKind::kFly, "fly"}};

// The director's options (subjects, seed, fps, motion blur, figure variant, crossing: handed to
// it as they are) and the session's.
struct SynthOptions : DirectorOptions {
  std::string out_dir;
  SynthKind kind = SynthKind::kAnimal;
  std::optional<StudioKind> studio;  // unset: the stage for figures, else the enclosure
  double seconds = 10.0;
  int width = 640;
  int height = 480;
  int cameras = 2;
  CameraView view = CameraView::kOblique;  // overhead: the enclosure only
  PixelFormat pixel_format = PixelFormat::kRGB8;
  double noise = 1.0;          // sensor noise scale (0: none)
  int threads = 1;             // cameras rendered in parallel
  bool write_mattes = true;    // the per-frame PNG mattes in truth/
  std::string codec = "ffv1";  // the videos' codec (core/recording_codecs.h)
  // Subjects stay out of view for this long at the start (truth pose "absent"),
  // as a studio records the empty enclosure first for the keyer to learn.
  double empty_lead_in_s = 0.0;

  // False with "FIELD: reason" lines in `why` (core/option_checks.h) for values out of range:
  // the director's fields by DirectorOptions::IsValid, narrowed to what a session renders.
  bool IsValid(std::string* why) const;
  int frames() const;
};

struct SynthSummary {
  std::string out_dir;
  int frames = 0;
  int cameras = 0;
  int subjects = 0;
  double fps = 0.0;
  double wall_s = 0.0;  // whole run
  double cpu_s = 0.0;   // whole run, CPU time of every thread (encoder threads included)
  // Stages in CPU seconds of the threads that ran them:
  double simulate_s = 0.0;                 // behaviour and scene building
  double render_s = 0.0;                   // ray casting, summed over cameras
  double sensor_s = 0.0;                   // noise and pixel format
  double encode_s = 0.0;                   // video writer
  double truth_s = 0.0;                    // mattes and tables
  std::map<std::string, int> pose_frames;  // subject-frames per pose label
  int wall_touch_frames = 0;               // subject-frames touching a wall
  // Seconds of footage per second of wall time (>= 1: all cameras kept up with real time).
  double RealTimeFactor() const { return wall_s > 0 && fps > 0 ? frames / fps / wall_s : 0.0; }
  // Camera-seconds of footage per CPU-second (>= 1: one core renders a camera in real time).
  double CpuRealTimeFactor() const {
    return cpu_s > 0 && fps > 0 ? frames * cameras / fps / cpu_s : 0.0;
  }
};

// Renders the session into options.out_dir (which must not exist or be empty).
// InputError("synth options", ...) for bad options, WorkError when writing fails.
SynthSummary RenderStudioSession(const SynthOptions& options);

}  // namespace ss::synth
