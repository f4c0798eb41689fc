#pragma once
// Importers for the 2D keypoints other tools write (docs/skeletons.md): DeepLabCut CSV,
// OpenPose per-frame JSON and COCO keypoint annotations. A JointMapping turns their
// keypoints into the joints of a skeleton definition; keypoints below the confidence
// threshold become missing joints.
#include <optional>
#include <string>

#include "animate/skeleton/joint_mapping.h"
#include "animate/skeleton/skeleton.h"

namespace ss {

// (Named apart from import/'s ImportOptions, the session importer's: one program holds both.)
struct SkeletonImportOptions {
  // Keypoints with a lower confidence become missing joints. Unset: the mapping file's
  // min_confidence, else the format's default (DeepLabCut 0.6 as its pcutoff, OpenPose 0.2,
  // COCO 0.5, which keeps v=1 "labelled, hidden" as confidence 0.5 and v=2 as 1).
  std::optional<float> min_confidence;
  std::string individual;  // DeepLabCut multi-animal: which individual (empty: the first)
  int person = 0;          // OpenPose: index into people[]; synth truth: the subject
  // COCO: the category whose annotations are read (-1: the first with keypoints)
  int category_id = -1;
  // False with "FIELD: reason" lines in `why` (core/option_checks.h) for values out of range.
  // Each importer refuses such options with InputError("skeleton import options", ...).
  bool IsValid(std::string* why) const;
};

// DeepLabCut's CSV: header rows scorer / [individuals] / bodyparts / coords (x, y,
// likelihood), then one row per frame starting with the frame index (or image path).
SkeletonSequence ImportDeepLabCutCsv(const std::string& path, const JointMapping& mapping,
                                     const SkeletonImportOptions& options = {});

// OpenPose's per-frame files (*_keypoints.json) in a folder, or one such file:
// people[person].pose_keypoints_2d = [x, y, c] * N. BODY_25 (N = 25) keypoints may be
// mapped by name (Body25KeypointNames()), any layout by index. A frame without the person
// has every joint missing.
SkeletonSequence ImportOpenPoseJson(const std::string& path, const JointMapping& mapping,
                                    const SkeletonImportOptions& options = {});

// A COCO keypoint file: one frame per image (by increasing image id; frame = image id),
// the annotation with the most labelled keypoints, keypoints = [x, y, v] * K with names
// from categories[].keypoints (Coco17KeypointNames() if absent).
SkeletonSequence ImportCocoKeypoints(const std::string& path, const JointMapping& mapping,
                                     const SkeletonImportOptions& options = {});

// The synthetic studio's joint truth (docs/synth.md): `<session>/truth/<camera>/joints.csv`
// (frame, subject, joint, name, x, y; extra columns ignored) for subject `options.person`.
// `path` is the session folder, its truth folder or the CSV itself; `camera` empty = the
// first camera in truth.json. Keypoints are the truth's joint names; every projected joint
// is present with confidence 1 (also when hidden behind the body: it is the truth). The
// clip is SESSION/CAMERA, as `skeleton track` names it, and fps comes from truth.json.
SkeletonSequence ImportSynthTruth(const std::string& path, const std::string& camera,
                                  const JointMapping& mapping,
                                  const SkeletonImportOptions& options = {});

// A mapping taking each joint of `def` from the keypoint of the same name.
JointMapping IdentityMapping(const SkeletonDef& def);

}  // namespace ss
