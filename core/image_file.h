#pragma once
// Images written to files, with the error the commands report.
#include <string>
#include <vector>

#include <opencv2/core.hpp>

namespace ss {

// Writes `image` to `path` in the format its extension names (cv::imwrite, `params` its flags).
// WorkError (path, "cannot write the WHAT", with OpenCV's reason when it gives one) on failure.
void WriteImageFile(const std::string& path, const cv::Mat& image, const std::string& what,
                    const std::vector<int>& params = {});

}  // namespace ss
