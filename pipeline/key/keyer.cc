#include "pipeline/key/keyer.h"

#include <string>

#include "core/error.h"
#include "core/option_checks.h"

namespace ss {
namespace {

// Inclusive cell bounds, grown cell by cell.
struct GrownCellBox {
  int x0, y0, x1, y1;
  cv::Rect Rect() const { return cv::Rect(x0, y0, x1 - x0 + 1, y1 - y0 + 1); }
};

std::string SizeText(cv::Size s) {
  return std::to_string(s.width) + "x" + std::to_string(s.height);
}

}  // namespace

bool GridOptions::IsValid(std::string* why) const {
  OptionProblems check(why);
  check.Within(step, Between(2, 64), "step", "2 to 64 px");
  check.Within(margin_px, AtLeast(0), "margin_px", "a number >= 0");
  check.Within(shadow_reach_cells, AtLeast(0), "shadow_reach_cells", "a number >= 0");
  return check.ok();
}

Keyer::Keyer(GridOptions grid) : grid_(grid) {
  if (std::string why; !grid_.IsValid(&why)) throw InputError("keyer grid options", why);
}

void Keyer::StartTraining(const std::vector<cv::Mat>& empty_bgr, const std::string& keyer) {
  if (empty_bgr.empty()) throw InputError(keyer + " training", "no frames of the empty enclosure");
  const cv::Size size = empty_bgr.front().size();
  for (size_t i = 0; i < empty_bgr.size(); ++i) {
    const cv::Mat& f = empty_bgr[i];
    const std::string what = keyer + " training frame " + std::to_string(i);
    if (f.empty()) throw InputError(what, "empty image");
    if (f.type() != CV_8UC3) throw InputError(what, "expected 8-bit BGR (CV_8UC3)");
    if (f.size() != size) {
      throw InputError(what,
                       "size " + SizeText(f.size()) + " differs from frame 0's " + SizeText(size));
    }
  }
  size_ = size;
  cols_ = (size.width + grid_.step - 1) / grid_.step;
  rows_ = (size.height + grid_.step - 1) / grid_.step;
}

void Keyer::Key(const Frame& frame, cv::Mat& bgr_scratch, Matte& matte) const {
  const bool packed = frame.format == PixelFormat::kBGR8 || frame.format == PixelFormat::kRGB8;
  const size_t bytes = FrameBytes(PixelFormat::kBGR8, frame.width, frame.height);
  if (packed && frame.data != nullptr && frame.size >= bytes && bytes > 0) {
    // No copy, no conversion: key the frame's own bytes.
    const cv::Mat view(frame.height, frame.width, CV_8UC3, const_cast<uint8_t*>(frame.data));
    Key(view, frame.format == PixelFormat::kRGB8 ? ChannelOrder::kRgb : ChannelOrder::kBgr, matte);
    return;
  }
  if (frame.format == PixelFormat::kMono8) {
    throw InputError(
        "frame " + std::to_string(frame.sequence),
        "mono8 frames carry no colour for the " + name() +
            " keyer; a colour format is needed (rgb8, bgr8, bayer_*, yuyv, nv12, mjpeg)");
  }
  ToBgr(frame, bgr_scratch);
  Key(bgr_scratch, ChannelOrder::kBgr, matte);
}

void Keyer::Key(const cv::Mat& image, ChannelOrder order, Matte& matte) const {
  if (!trained()) throw WorkError(name() + " keyer", "used before Train() saw the empty enclosure");
  if (image.type() != CV_8UC3) {
    throw InputError("frame",
                     "expected 8-bit 3-channel pixels (CV_8UC3) for " + name() + " keying");
  }
  if (image.size() != size_) {
    throw InputError("frame", "size " + SizeText(image.size()) + " differs from the " +
                                  SizeText(size_) + " the " + name() + " keyer was trained on");
  }
  Prepare(matte);
  CoarsePass(image, order, matte.coarse);
  FindRegions(matte.coarse, matte.regions);
  for (const KeyRegion& r : matte.regions) {
    const int x0 = r.box.x, x1 = r.box.x + r.box.width;
    for (int y = r.box.y; y < r.box.y + r.box.height; ++y) {
      FineRow(image.ptr<uint8_t>(y), order, y, x0, x1, matte.alpha.ptr<uint8_t>(y),
              matte.shadow.ptr<uint8_t>(y), matte.colour.ptr<uint8_t>(y));
    }
  }
}

void Keyer::Prepare(Matte& matte) const {
  if (matte.alpha.size() != size_ || matte.alpha.type() != CV_8U || matte.shadow.size() != size_ ||
      matte.shadow.type() != CV_8U || matte.colour.size() != size_ ||
      matte.colour.type() != CV_8UC3) {
    matte.alpha.create(size_, CV_8U);
    matte.alpha.setTo(0);
    matte.shadow.create(size_, CV_8U);
    matte.shadow.setTo(0);
    matte.colour.create(size_, CV_8UC3);
  } else {
    // Only last frame's regions can hold anything but zeros.
    for (const KeyRegion& r : matte.regions) {
      const cv::Rect box = r.box & cv::Rect(0, 0, size_.width, size_.height);
      matte.alpha(box).setTo(0);
      matte.shadow(box).setTo(0);
    }
  }
  matte.regions.clear();
  CoarseGrid& g = matte.coarse;
  g.step = grid_.step;
  g.cols = cols_;
  g.rows = rows_;
  const size_t n = static_cast<size_t>(cols_) * rows_;
  g.foreground.resize(n);
  g.shade.resize(n);
  g.dilated.resize(n);
  g.label.assign(n, 0);
  g.queue.clear();
  g.queue.reserve(n);
}

void Keyer::CoarsePass(const cv::Mat& image, ChannelOrder order, CoarseGrid& g) const {
  for (int cy = 0; cy < rows_; ++cy) {
    SampleRow(image.ptr<uint8_t>(SampleY(cy)), order, cy,
              &g.foreground[static_cast<size_t>(cy) * cols_],
              &g.shade[static_cast<size_t>(cy) * cols_]);
  }
}

void Keyer::FindRegions(CoarseGrid& g, std::vector<KeyRegion>& regions) const {
  const int cols = cols_, rows = rows_;
  // Dilate the foreground by one cell: vertically, then horizontally in place.
  for (int cy = 0; cy < rows; ++cy) {
    const uint8_t* up = &g.foreground[static_cast<size_t>(std::max(cy - 1, 0)) * cols];
    const uint8_t* mid = &g.foreground[static_cast<size_t>(cy) * cols];
    const uint8_t* down = &g.foreground[static_cast<size_t>(std::min(cy + 1, rows - 1)) * cols];
    uint8_t* out = &g.dilated[static_cast<size_t>(cy) * cols];
    for (int cx = 0; cx < cols; ++cx) out[cx] = up[cx] | mid[cx] | down[cx];
    uint8_t prev = 0;
    for (int cx = 0; cx < cols; ++cx) {
      const uint8_t here = out[cx];
      const uint8_t next = cx + 1 < cols ? out[cx + 1] : 0;
      out[cx] = prev | here | next;
      prev = here;
    }
  }

  // 8-connected components of the dilated foreground.
  auto& queue = g.queue;
  const int n = cols * rows;
  for (int start = 0; start < n; ++start) {
    if (!g.dilated[start] || g.label[start]) continue;
    const int id = static_cast<int>(regions.size()) + 1;
    KeyRegion region;
    region.id = id;
    GrownCellBox box{start % cols, start / cols, start % cols, start / cols};
    size_t head = queue.size();
    queue.push_back(start);
    g.label[start] = id;
    while (head < queue.size()) {
      const int c = queue[head++];
      const int cx = c % cols, cy = c / cols;
      region.foreground_cells += g.foreground[c];
      box = {std::min(box.x0, cx), std::min(box.y0, cy), std::max(box.x1, cx),
             std::max(box.y1, cy)};
      for (int ny = std::max(cy - 1, 0); ny <= std::min(cy + 1, rows - 1); ++ny) {
        for (int nx = std::max(cx - 1, 0); nx <= std::min(cx + 1, cols - 1); ++nx) {
          const int nc = ny * cols + nx;
          if (g.dilated[nc] && !g.label[nc]) {
            g.label[nc] = id;
            queue.push_back(nc);
          }
        }
      }
    }
    region.cells = box.Rect();
    regions.push_back(region);
  }
  if (regions.empty()) return;

  // Grow each region through adjacent shaded cells, breadth first, a bounded
  // number of cells: its contact shadow belongs to it.
  size_t level_begin = 0, level_end = queue.size();
  for (int level = 0; level < grid_.shadow_reach_cells && level_begin < level_end; ++level) {
    for (size_t i = level_begin; i < level_end; ++i) {
      const int c = queue[i];
      const int id = g.label[c];
      const int cx = c % cols, cy = c / cols;
      for (int ny = std::max(cy - 1, 0); ny <= std::min(cy + 1, rows - 1); ++ny) {
        for (int nx = std::max(cx - 1, 0); nx <= std::min(cx + 1, cols - 1); ++nx) {
          const int nc = ny * cols + nx;
          if (g.shade[nc] && !g.label[nc]) {
            g.label[nc] = id;
            queue.push_back(nc);
            regions[id - 1].cells |= cv::Rect(nx, ny, 1, 1);
          }
        }
      }
    }
    level_begin = level_end;
    level_end = queue.size();
  }

  const cv::Rect frame(0, 0, size_.width, size_.height);
  const int s = grid_.step, m = grid_.margin_px;
  for (KeyRegion& r : regions) {
    r.box = cv::Rect(r.cells.x * s - m, r.cells.y * s - m, r.cells.width * s + 2 * m,
                     r.cells.height * s + 2 * m) &
            frame;
  }
  for (size_t i = 0; i < regions.size(); ++i) {
    for (size_t j = i + 1; j < regions.size(); ++j) {
      if ((regions[i].box & regions[j].box).area() > 0) {
        regions[i].overlaps_other = true;
        regions[j].overlaps_other = true;
      }
    }
  }
}

}  // namespace ss
