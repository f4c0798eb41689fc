// The 2D skeleton importers (animate/skeleton/importers.h): the first byte picks the format
// (DeepLabCut CSV, OpenPose JSON, COCO keypoints JSON), the rest is the file.
#include "animate/skeleton/importers.h"
#include "animate/skeleton/skeleton.h"
#include "tests/fuzz/fuzz_support.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size == 0) return 0;
  static const ss::JointMapping mapping = ss::IdentityMapping(ss::HumanSkeleton());
  const int format = data[0] % 3;
  const char* names[] = {"dlc.csv", "frame_keypoints.json", "coco.json"};
  const std::string path = ss::fuzz::WriteFile(names[format], data + 1, size - 1);
  return ss::fuzz::Expect([&] {
    if (format == 0) ss::ImportDeepLabCutCsv(path, mapping);
    if (format == 1) ss::ImportOpenPoseJson(path, mapping);
    if (format == 2) ss::ImportCocoKeypoints(path, mapping);
  });
}
