#include "pipeline/extract/extractor.h"

#include <algorithm>
#include <string>

#include "core/contact_point.h"
#include "core/error.h"
#include "core/option_checks.h"

namespace ss {
namespace {

struct RowScan {
  int max;
  uint32_t sum;
};

// Largest value and sum of a row: two reductions the vectorizer fuses.
inline RowScan ScanRow(const uint8_t* __restrict p, int n) {
  uint8_t m = 0;
  uint32_t s = 0;
  for (int i = 0; i < n; ++i) {
    m = std::max(m, p[i]);
    s += p[i];
  }
  return {m, s};
}

inline int RowMax(const uint8_t* __restrict p, int n) {
  uint8_t m = 0;
  for (int i = 0; i < n; ++i) m = std::max(m, p[i]);
  return m;
}

// First index in [0, end) with p >= v, or `end` when there is none.
inline int FirstAtLeast(const uint8_t* p, int end, int v) {
  int i = 0;
  while (i < end && p[i] < v) ++i;
  return i;
}

// Last index in (begin, n) with p >= v, or `begin` when there is none.
inline int LastAtLeast(const uint8_t* p, int n, int begin, int v) {
  int i = n - 1;
  while (i > begin && p[i] < v) --i;
  return i;
}

// Tight box of the values >= v in `image`; empty when there are none.
cv::Rect TightBox(const cv::Mat& image, int v) {
  int x0 = image.cols, x1 = -1, y0 = -1, y1 = -1;
  for (int y = 0; y < image.rows; ++y) {
    const uint8_t* p = image.ptr<uint8_t>(y);
    if (RowMax(p, image.cols) < v) continue;
    if (y0 < 0) y0 = y;
    y1 = y;
    x0 = FirstAtLeast(p, x0, v);  // searches only left of the box so far
    x1 = LastAtLeast(p, image.cols, x1, v);
  }
  if (y0 < 0) return {};
  return {x0, y0, x1 - x0 + 1, y1 - y0 + 1};
}

// A bbox-sized Mat over `bytes`, grown if needed (never shrunk).
cv::Mat View(std::vector<uint8_t>& bytes, cv::Size size, int type) {
  const size_t need = static_cast<size_t>(size.area()) * CV_ELEM_SIZE(type);
  if (bytes.size() < need) bytes.resize(need);
  return cv::Mat(size, type, bytes.data());
}

}  // namespace

bool ExtractorOptions::IsValid(std::string* why) const {
  OptionProblems check(why);
  check.Within(min_area, AtLeast(1), "min_area", "at least 1 pixel");
  check.Within(margin_px, AtLeast(0), "margin_px", "a number >= 0");
  check.Within(alpha_min, Between(1, 255), "alpha_min", "a level 1..255");
  check.Within(shadow_min, Between(1, 255), "shadow_min", "a level 1..255");
  std::string part;
  check.Nested(contact.IsValid(&part), "contact.", part);
  return check.ok();
}

Extractor::Extractor(ExtractorOptions options) : options_(options) {
  if (std::string why; !options_.IsValid(&why)) throw InputError("extract options", why);
}

const std::vector<Candidate>& Extractor::Extract(const Matte& matte) {
  candidates_.resize(matte.regions.size());
  if (storage_.size() < matte.regions.size()) storage_.resize(matte.regions.size());
  size_t kept = 0;
  for (const KeyRegion& r : matte.regions) {
    if (Cut(matte, r, kept)) ++kept;
  }
  candidates_.resize(kept);
  dropped_last_ = static_cast<int>(matte.regions.size() - kept);
  ++totals_.frames;
  totals_.candidates += kept;
  totals_.noise_dropped += dropped_last_;
  return candidates_;
}

bool Extractor::Cut(const Matte& matte, const KeyRegion& r, size_t index) {
  const cv::Rect box = r.box;
  cv::Mat alpha = matte.alpha(box), shadow = matte.shadow(box);
  if (r.overlaps_other) {
    // Another region's box reaches into this one: blank the other region's cells.
    alpha.copyTo(masked_alpha_);
    shadow.copyTo(masked_shadow_);
    const CoarseGrid& g = matte.coarse;
    for (int y = 0; y < box.height; ++y) {
      const int cy = std::min((box.y + y) / g.step, g.rows - 1);
      for (int x = 0; x < box.width;) {
        const int cx = (box.x + x) / g.step;
        const int end = std::min((cx + 1) * g.step - box.x, box.width);
        const int id = g.label[static_cast<size_t>(cy) * g.cols + std::min(cx, g.cols - 1)];
        if (id != 0 && id != r.id) {
          std::fill(masked_alpha_.ptr<uint8_t>(y) + x, masked_alpha_.ptr<uint8_t>(y) + end, 0);
          std::fill(masked_shadow_.ptr<uint8_t>(y) + x, masked_shadow_.ptr<uint8_t>(y) + end, 0);
        }
        x = end;
      }
    }
    alpha = masked_alpha_;
    shadow = masked_shadow_;
  }

  // The subject: alpha box, area, whether any alpha > 1/2.
  const int v = options_.alpha_min;
  int x0 = box.width, x1 = -1, y0 = -1, y1 = -1, lowest = -1;
  uint64_t sum = 0;
  for (int y = 0; y < box.height; ++y) {
    const uint8_t* a = alpha.ptr<uint8_t>(y);
    const RowScan s = ScanRow(a, box.width);
    sum += s.sum;
    if (s.max > 127) lowest = y;
    if (s.max < v) continue;
    if (y0 < 0) y0 = y;
    y1 = y;
    x0 = FirstAtLeast(a, x0, v);  // searches only left of the box so far
    x1 = LastAtLeast(a, box.width, x1, v);
  }
  const double area = static_cast<double>(sum) / 255.0;
  if (area < options_.min_area || lowest < 0 || y0 < 0) return false;

  Candidate& c = candidates_[index];
  c.region = r.id;
  c.area = area;
  const cv::Size frame = matte.alpha.size();
  c.touches_border = box.x + x0 == 0 || box.y + y0 == 0 || box.x + x1 == frame.width - 1 ||
                     box.y + y1 == frame.height - 1;

  // The box: subject + margin, grown to hold the shadow, within the region.
  const int m = options_.margin_px;
  cv::Rect local(cv::Point(x0 - m, y0 - m), cv::Point(x1 + 1 + m, y1 + 1 + m));
  const cv::Rect shade = TightBox(shadow, options_.shadow_min);
  if (!shade.empty()) local |= shade;
  local &= cv::Rect(0, 0, box.width, box.height);
  c.bbox = local + box.tl();

  Storage& st = storage_[index];
  c.alpha = View(st.alpha, local.size(), CV_8U);
  c.colour = View(st.colour, local.size(), CV_8UC3);
  c.shadow = View(st.shadow, local.size(), CV_8U);
  alpha(local).copyTo(c.alpha);
  matte.colour(c.bbox).copyTo(c.colour);
  shadow(local).copyTo(c.shadow);

  // The contact point (core/contact_point.h), from the subject's own alpha.
  cv::Point2d contact;
  ContactPoint(c.alpha, &contact, options_.contact);
  c.contact_point = contact + cv::Point2d(c.bbox.tl());
  return true;
}

}  // namespace ss
