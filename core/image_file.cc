#include "core/image_file.h"

#include <opencv2/imgcodecs.hpp>

#include "core/error.h"

namespace ss {

void WriteImageFile(const std::string& path, const cv::Mat& image, const std::string& what,
                    const std::vector<int>& params) {
  bool ok = false;
  try {
    ok = cv::imwrite(path, image, params);
  } catch (const cv::Exception& e) {
    throw WorkError(path, "cannot write the " + what + ": " + e.what());
  }
  if (!ok) throw WorkError(path, "cannot write the " + what);
}

}  // namespace ss
