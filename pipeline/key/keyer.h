#pragma once
// The keyer interface and the coarse-to-fine scheme both keyers share
// (docs/keying.md). A coarse pass tests one pixel per `step` x `step` cell;
// foreground cells, dilated by one cell and grown through adjacent shaded
// cells, form connected regions; the full-resolution soft key, despill and
// shadow run only inside each region's box. The cost of a frame is then a
// few percent of its pixels plus the subject's own box.
#include <algorithm>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "core/frame.h"
#include "pipeline/key/matte.h"

namespace ss {

// Byte order of 3-channel pixels. The keyers read either in place; the
// matte's colour layer is BGR (OpenCV's order) either way.
enum class ChannelOrder { kBgr, kRgb };

struct GridOptions {
  int step = 8;       // coarse sampling step, px (2..64); anything >= step + 2 px across is sampled
  int margin_px = 6;  // added around each region's cell box, px (>= 0)
  // shaded cells join a region up to this many cells away from it (>= 0)
  int shadow_reach_cells = 6;
  // False with "FIELD: reason" lines in `why` (core/option_checks.h) for values out of range.
  bool IsValid(std::string* why) const;
  bool operator==(const GridOptions&) const = default;
};

class Keyer {
 public:
  virtual ~Keyer() = default;
  virtual std::string name() const = 0;

  // Learns the empty enclosure from BGR frames (one or more, all one size).
  // Throws InputError naming the frame and the reason.
  virtual void Train(const std::vector<cv::Mat>& empty_bgr) = 0;
  bool trained() const { return size_.width > 0; }
  // CV_8U, the trained size: 255 where the empty enclosure is background this keyer keys
  // (a chroma key's green), 0 where no subject can ever be seen against it (the room, a wall's
  // outside, a cable). Empty when the keyer keys every pixel (a clean plate).
  virtual cv::Mat KeyableMask() const { return {}; }
  cv::Size size() const { return size_; }  // the trained frame size
  const GridOptions& grid() const { return grid_; }

  // Keys one BGR frame into `matte`, reusing its buffers. Const and free of
  // shared state: one keyer may serve several threads, each with its own Matte.
  // Throws InputError on a frame of the wrong type or size, WorkError if untrained.
  void Key(const cv::Mat& bgr, Matte& matte) const { Key(bgr, ChannelOrder::kBgr, matte); }
  // The same for an 8-bit 3-channel image in either channel order, keyed in place.
  void Key(const cv::Mat& image, ChannelOrder order, Matte& matte) const;
  // Any pixel format: BGR8 and RGB8 keyed in place, the others converted to BGR
  // in `bgr_scratch` first (core/frame.h ToBgr: bilinear demosaic, YUV 4:2:x).
  // Throws InputError for mono8 (both keys need colour: in grey a chroma key
  // has nothing to key and a darker subject looks like a shadow) and for a
  // malformed frame.
  void Key(const Frame& frame, cv::Mat& bgr_scratch, Matte& matte) const;

 protected:
  explicit Keyer(GridOptions grid);
  // Tests the samples of cell row `cell_row`; `row` is image row SampleY(cell_row)
  // in channel order `order`. Sets foreground[cx] and shade[cx] to 0 or 1 for every cell.
  virtual void SampleRow(const uint8_t* row, ChannelOrder order, int cell_row, uint8_t* foreground,
                         uint8_t* shade) const = 0;
  // Full-resolution key of pixels [x0, x1) of image row y. Output pointers
  // address pixel 0 of the row (colour: 3 bytes per pixel, BGR).
  virtual void FineRow(const uint8_t* row, ChannelOrder order, int y, int x0, int x1,
                       uint8_t* alpha, uint8_t* shadow, uint8_t* colour) const = 0;
  // Checks training frames (non-empty, 8-bit BGR, one size); sets size_ and the grid shape.
  void StartTraining(const std::vector<cv::Mat>& empty_bgr, const std::string& keyer);

  int SampleX(int cx) const { return std::min(cx * grid_.step + grid_.step / 2, size_.width - 1); }
  int SampleY(int cy) const { return std::min(cy * grid_.step + grid_.step / 2, size_.height - 1); }

  GridOptions grid_;
  cv::Size size_;            // trained frame size; width 0 until trained
  int cols_ = 0, rows_ = 0;  // coarse cells

 private:
  void Prepare(Matte& matte) const;
  void CoarsePass(const cv::Mat& image, ChannelOrder order, CoarseGrid& coarse) const;
  void FindRegions(CoarseGrid& coarse, std::vector<KeyRegion>& regions) const;
};

}  // namespace ss
