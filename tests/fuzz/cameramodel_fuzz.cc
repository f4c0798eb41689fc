// An mrcal .cameramodel (core/camera_model.h), read through mrcal's own parser.
#include "core/camera_model.h"
#include "tests/fuzz/fuzz_support.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string path = ss::fuzz::WriteFile("cam0.cameramodel", data, size);
  return ss::fuzz::Expect([&] { ss::CameraModel::Read(path); });
}
