#include "calib/inputs.h"

#include <algorithm>
#include <filesystem>
#include <set>

#include <opencv2/imgcodecs.hpp>

#include "capture/replay/replay_source.h"
#include "core/error.h"
#include "core/frame.h"
#include "core/log.h"
#include "core/option_checks.h"
#include "core/session.h"

namespace ss::calib {

namespace fs = std::filesystem;

bool IsSessionDir(const std::string& path) {
  std::error_code ec;
  return fs::is_directory(path, ec) && fs::exists(fs::path(path) / "session.json", ec);
}

bool SampleOptions::IsValid(std::string* why) const {
  OptionProblems check(why);
  check.Within(every, AtLeast(0), "every", "0 (spread max_views) or a step >= 1");
  check.Within(max_views, AtLeast(1), "max_views", "at least 1 view");
  check.Within(first, AtLeast(0), "first", "a frame index >= 0");
  check.Within(count, AtLeast(0), "count", "0 (to the end) or a number of frames");
  return check.ok();
}

std::vector<CameraViews> DetectInSession(const std::string& dir, const BoardSpec& board,
                                         const DetectOptions& detect, const SampleOptions& sample) {
  if (std::string why; !sample.IsValid(&why)) throw InputError("frame sampling options", why);
  if (std::string why; !detect.IsValid(&why)) throw InputError("board detection options", why);
  const SessionInfo info = ReadSessionInfo(dir);
  std::vector<CameraViews> out;
  std::vector<int> wanted(info.cameras.size(), -1), every(info.cameras.size(), 1);
  for (const auto& name : sample.cameras) {
    const bool known = std::any_of(info.cameras.begin(), info.cameras.end(),
                                   [&](const auto& c) { return c.name == name; });
    if (!known)
      throw InputError(dir + "/session.json", "no camera named \"" + name + "\" in the session");
  }
  for (size_t i = 0; i < info.cameras.size(); ++i) {
    const auto& c = info.cameras[i];
    if (!sample.cameras.empty() &&
        std::find(sample.cameras.begin(), sample.cameras.end(), c.name) == sample.cameras.end()) {
      continue;
    }
    wanted[i] = static_cast<int>(out.size());
    CameraViews v;
    v.name = c.name;
    v.width = c.width;
    v.height = c.height;
    if (!c.model.empty()) v.model_path = (fs::path(dir) / c.model).string();
    const auto rows = ReadFrameCsv((fs::path(dir) / c.frames_csv).string());
    int span = static_cast<int>(rows.size()) - sample.first;
    if (sample.count > 0) span = std::min(span, sample.count);
    every[i] = sample.every > 0
                   ? sample.every
                   : std::max(1, (span + sample.max_views - 1) / std::max(1, sample.max_views));
    out.push_back(std::move(v));
  }
  if (out.empty())
    throw InputError(dir + "/session.json", "the session has no camera to calibrate");
  ReplaySource source(dir);
  std::vector<int> index(info.cameras.size(), -1);
  cv::Mat bgr;
  while (auto frame = source.Next()) {
    const int cam = frame->camera;
    const int i = ++index[cam];
    if (wanted[cam] < 0 || i < sample.first ||
        (sample.count > 0 && i >= sample.first + sample.count) ||
        (i - sample.first) % every[cam] != 0) {
      continue;
    }
    CameraViews& v = out[wanted[cam]];
    const std::string source_name = v.name + " frame " + std::to_string(i);
    BoardView view;
    try {
      ToBgr(*frame, bgr);
      view = DetectBoard(board, bgr, detect, source_name);
    } catch (const InputError& e) {
      view.source = source_name;
      view.rejection = std::string("unreadable frame: ") + e.what();
    }
    v.views.push_back(std::move(view));
    v.frames.push_back(i);
  }
  const auto stats = source.camera_stats();
  for (const auto& s : stats) {
    for (const auto& problem : s.problems) Log("calib.inputs")->warn("{}", problem);
  }
  return out;
}

CameraViews DetectInImages(const std::vector<std::string>& paths, const BoardSpec& board,
                           const DetectOptions& detect, const std::string& name) {
  if (std::string why; !detect.IsValid(&why)) throw InputError("board detection options", why);
  static const std::set<std::string> kImageExt = {".png", ".jpg",  ".jpeg", ".bmp",
                                                  ".tif", ".tiff", ".pgm",  ".ppm"};
  std::vector<std::string> files;
  for (const auto& p : paths) {
    std::error_code ec;
    if (fs::is_directory(p, ec)) {
      std::vector<std::string> in_dir;
      for (const auto& e : fs::directory_iterator(p)) {
        std::string ext = e.path().extension().string();
        std::transform(ext.begin(), ext.end(), ext.begin(), ::tolower);
        if (e.is_regular_file() && kImageExt.count(ext)) in_dir.push_back(e.path().string());
      }
      std::sort(in_dir.begin(), in_dir.end());
      files.insert(files.end(), in_dir.begin(), in_dir.end());
    } else if (fs::exists(p, ec)) {
      files.push_back(p);
    } else {
      throw InputError(p, "no such file or folder");
    }
  }
  if (files.empty()) throw InputError(paths.empty() ? "IMAGES" : paths.front(), "no image files");
  CameraViews out;
  out.name = name;
  for (size_t i = 0; i < files.size(); ++i) {
    cv::Mat image;
    try {
      image = cv::imread(files[i], cv::IMREAD_COLOR);
    } catch (const cv::Exception&) {
    }
    BoardView view;
    if (image.empty()) {
      view.source = files[i];
      view.rejection = "unreadable image";
    } else {
      if (out.width == 0) out.width = image.cols, out.height = image.rows;
      if (image.cols != out.width || image.rows != out.height) {
        throw InputError(files[i], "image is " + std::to_string(image.cols) + "x" +
                                       std::to_string(image.rows) + " but the first was " +
                                       std::to_string(out.width) + "x" +
                                       std::to_string(out.height) + " (one camera per call)");
      }
      view = DetectBoard(board, image, detect, files[i]);
    }
    out.views.push_back(std::move(view));
    out.frames.push_back(static_cast<int>(i));
  }
  if (out.width == 0)
    throw InputError(files.front(),
                     "none of the " + std::to_string(files.size()) + " images could be read");
  return out;
}

}  // namespace ss::calib
