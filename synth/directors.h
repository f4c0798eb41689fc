#pragma once
// The directors of the three kinds of session (snapshot.h): animals in the
// enclosure, articulated figures on the stage, calibration boards. Each refuses options that are
// not valid (DirectorOptions::IsValid) with an InputError.
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "synth/lens.h"
#include "synth/scene.h"
#include "synth/snapshot.h"

namespace ss::synth {

struct DirectorOptions {
  int subjects = 1;
  uint64_t seed = 1;
  double fps = 30.0;
  bool motion_blur = false;  // 4 time slices spread over half a frame interval
  int figure_variant = 0;    // 0: the reference figure; 1: differently proportioned
  // Animals ignore each other (they no longer keep apart): their paths cross and their
  // silhouettes meet in the cameras' images (truth/<cam>/overlaps.csv), as two subjects in one
  // blob. They pass through each other where they meet.
  bool crossing = false;
  // False with "FIELD: reason" lines in `why` (core/option_checks.h) for values out of range.
  bool IsValid(std::string* why) const;
};

// `subjects` animals with their behaviour models, placed apart on the floor.
std::unique_ptr<Director> MakeAnimalDirector(const Studio& studio,
                                             const std::vector<SynthCamera>& cameras,
                                             const DirectorOptions& options);

// `subjects` flies (synth/fly.h): still most of the time, grooming, walking and darting.
std::unique_ptr<Director> MakeFlyDirector(const Studio& studio, const DirectorOptions& options);

// Calibration boards (a chessboard and a ChArUco board) held in many poses
// before each camera in turn, then lying flat on the floor. No subjects.
std::unique_ptr<Director> MakeCalibrationDirector(const Studio& studio,
                                                  const std::vector<SynthCamera>& cameras,
                                                  const DirectorOptions& options, double seconds);

// Articulated figures on the stage: idle, walking, turning to face camera 0 and
// holding the arm poses Y, M, C, A. The timeline depends on the seed only, so
// both builds (options.figure_variant) perform the same sequence.
std::unique_ptr<Director> MakeFigureDirector(const Studio& studio,
                                             const std::vector<SynthCamera>& cameras,
                                             const DirectorOptions& options);

}  // namespace ss::synth
