#include "pipeline/run/bank_scale.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <optional>
#include <vector>

#include <spdlog/fmt/fmt.h>

#include "core/error.h"

namespace ss {
namespace {

Eigen::Vector2d Centre(const GroundPolygon& floor) {
  Eigen::Vector2d centre = Eigen::Vector2d::Zero();
  for (const Eigen::Vector2d& v : floor.vertices()) centre += v;
  return centre / static_cast<double>(floor.vertices().size());
}

bool InImage(const CameraModel& model, const Eigen::Vector2d& px) {
  return std::isfinite(px.x()) && std::isfinite(px.y()) && px.x() >= 0 && px.y() >= 0 &&
         px.x() <= model.width() && px.y() <= model.height();
}

// The camera sees the ground point in its image: it projects inside, and the ray back through that
// pixel points at it (a strongly distorting lens can fold points far outside its view back into the
// image).
bool Sees(const CameraModel& model, const Eigen::Vector3d& point) {
  const Eigen::Vector2d px = model.ProjectGround(point);
  if (!InImage(model, px)) return false;
  const Ray ray = model.RayInGround(px);
  const Eigen::Vector3d to = (point - ray.origin).normalized();
  return ray.direction.allFinite() && ray.direction.normalized().dot(to) > 0.9999;
}

// Two significant digits, rounded down: 287 -> 280, 1234 -> 1200, 47.9 -> 47.
double RoundDown(double v) {
  if (!(v > 0)) return 0;
  const double step = std::pow(10.0, std::floor(std::log10(v)) - 1);
  return std::max(1.0, std::floor(v / step) * step);
}

std::string Num(double v) { return fmt::format("{:g}", v); }

}  // namespace

double FloorPixelsPerMetre(const CameraModel& model, const GroundPolygon& floor) {
  if (floor.empty()) return 0;
  const Eigen::Vector2d centre = Centre(floor);
  const double step = 0.01;
  const Eigen::Vector2d p = model.ProjectGround({centre.x(), centre.y(), 0.0});
  const Eigen::Vector2d px = model.ProjectGround({centre.x() + step, centre.y(), 0.0});
  const Eigen::Vector2d py = model.ProjectGround({centre.x(), centre.y() + step, 0.0});
  if (!Sees(model, {centre.x(), centre.y(), 0.0})) return 0;
  const double s = ((px - p).norm() + (py - p).norm()) / (2 * step);
  return std::isfinite(s) ? s : 0.0;
}

double SeenFloorPixelsPerMetre(const CameraModel& model, const GroundPolygon& floor) {
  if (floor.empty() || model.width() <= 0 || model.height() <= 0) return 0;
  // A 32x24 grid of pixel centres over the image; each one whose ray meets the floor inside the
  // polygon (in front of the camera) gives the image's resolution of the floor there.
  constexpr int kCols = 32, kRows = 24;
  constexpr double kStep = 0.01;
  std::vector<double> seen;
  seen.reserve(kCols * kRows);
  for (int r = 0; r < kRows; ++r) {
    for (int c = 0; c < kCols; ++c) {
      const Eigen::Vector2d px((c + 0.5) * model.width() / kCols,
                               (r + 0.5) * model.height() / kRows);
      const std::optional<Eigen::Vector3d> hit = IntersectGround(model.RayInGround(px));
      if (!hit || !floor.Contains(hit->head<2>()) || !Sees(model, *hit)) continue;
      const Eigen::Vector3d& g = *hit;
      const Eigen::Vector2d p = model.ProjectGround(g);
      const Eigen::Vector2d dx = model.ProjectGround(g + Eigen::Vector3d(kStep, 0, 0));
      const Eigen::Vector2d dy = model.ProjectGround(g + Eigen::Vector3d(0, kStep, 0));
      const double s = ((dx - p).norm() + (dy - p).norm()) / (2 * kStep);
      if (std::isfinite(s) && s > 0) seen.push_back(s);
    }
  }
  if (seen.empty()) return 0;
  auto mid = seen.begin() + static_cast<std::ptrdiff_t>(seen.size() / 2);
  std::nth_element(seen.begin(), mid, seen.end());
  return *mid;
}

double TallestVisibleM(const CameraModel& model, const GroundPolygon& floor) {
  if (floor.empty()) return 0;
  double min_x = floor.vertices()[0].x(), max_x = min_x, min_y = floor.vertices()[0].y(),
         max_y = min_y;
  for (const Eigen::Vector2d& v : floor.vertices()) {
    min_x = std::min(min_x, v.x()), max_x = std::max(max_x, v.x());
    min_y = std::min(min_y, v.y()), max_y = std::max(max_y, v.y());
  }
  // A 16x16 grid over the floor; on each seen point, the vertical line's top still in the image
  // (5 cm steps up to 10 m, then refined to 5 mm).
  constexpr int kGrid = 16;
  constexpr double kCoarse = 0.05, kFine = 0.005, kMax = 10.0;
  double tallest = 0;
  for (int i = 0; i <= kGrid; ++i) {
    for (int j = 0; j <= kGrid; ++j) {
      const Eigen::Vector2d g(min_x + (max_x - min_x) * i / kGrid,
                              min_y + (max_y - min_y) * j / kGrid);
      if (!floor.Contains(g) || !Sees(model, {g.x(), g.y(), 0.0})) continue;
      const auto seen = [&](double z) {
        return InImage(model, model.ProjectGround({g.x(), g.y(), z}));
      };
      double z = 0;
      while (z < kMax && seen(z + kCoarse)) z += kCoarse;
      while (z < kMax && seen(z + kFine)) z += kFine;
      if (!Sees(model, {g.x(), g.y(), z})) continue;  // folded back into the image by the lens
      tallest = std::max(tallest, z);
    }
  }
  return tallest;
}

BankScale ChooseBankScale(const BankScaleInputs& in) {
  if (in.bank_scales.size() > 1) {
    throw InputError(in.bank_path,
                     "its sprites are stored at " + std::to_string(in.bank_scales.size()) +
                         " billboard scales (" + Num(in.bank_scales.front()) + " to " +
                         Num(in.bank_scales.back()) + " px/m): one bank must use one scale");
  }
  if (in.bank_scales.size() == 1) {
    const double bank = in.bank_scales.front();
    if (in.configured > 0 && in.configured != bank) {
      throw InputError("pipeline.px_per_m",
                       "is " + Num(in.configured) + " but bank " + in.bank_path +
                           " stores its sprites at " + Num(bank) +
                           " px/m, and one bank keeps one scale: set pipeline.px_per_m to " +
                           Num(bank) + " or auto, or store into another bank");
    }
    return {bank, "the bank's own scale (it holds sprites at " + Num(bank) + " px/m)"};
  }
  if (in.configured > 0)
    return {in.configured, "pipeline.px_per_m " + Num(in.configured) + " (configured)"};

  // auto, empty bank: the finest camera's resolution of the floor it sees, capped by what fits.
  double finest = 0, tallest = 0;
  for (const CameraModel* m : in.models) {
    finest = std::max(finest, SeenFloorPixelsPerMetre(*m, in.floor));
    tallest = std::max(tallest, TallestVisibleM(*m, in.floor));
  }
  if (!(finest > 0)) {
    throw InputError("pipeline.px_per_m",
                     "auto: no camera sees the floor, so the billboard scale cannot be chosen "
                     "from the cameras; give pipeline.px_per_m a number");
  }
  // The billboard of a subject `tallest` high: ceil((tallest + margin) * s) + 1 <= max_side_px.
  const double fit = tallest > 0 ? (in.max_side_px - 2) / (tallest + in.margin_m) : finest;
  const double chosen = RoundDown(std::min(finest, fit));
  std::string why = fmt::format(
      "auto: the finest camera sees the floor at {:.0f} px/m (the median over its view of the "
      "floor); the tallest thing a camera "
      "sees whole on the "
      "floor is {:.2f} m, which fits {} px up to {:.0f} px/m; {} px/m (two digits, rounded down)",
      finest, tallest, in.max_side_px, fit, Num(chosen));
  return {chosen, why};
}

namespace {

double RecordedScale(const Bank& bank, const std::string& text) {
  char* end = nullptr;
  const double v = std::strtod(text.c_str(), &end);
  if (end == text.c_str() || *end != '\0' || !(v > 0) || !std::isfinite(v)) {
    throw WorkError(bank.path(), std::string("meta '") + kBankScaleMetaKey + "' is \"" + text +
                                     "\", not a scale in px/m (the bank is damaged)");
  }
  return v;
}

}  // namespace

BankScale ChooseAndKeepBankScale(BankWriter& bank, BankScaleInputs in) {
  in.bank_scales = bank.BillboardScales();
  if (const std::optional<std::string> text = bank.GetMeta(kBankScaleMetaKey)) {
    const double recorded = RecordedScale(bank, *text);
    if (in.bank_scales.empty() && in.configured > 0 && recorded != in.configured) {
      // No sprite is stored yet (a station ran without a session): a configured number decides.
      bank.SetMeta(kBankScaleMetaKey, fmt::format("{:.17g}", in.configured));
    } else {
      in.bank_scales.push_back(recorded);
      std::sort(in.bank_scales.begin(), in.bank_scales.end());
      in.bank_scales.erase(std::unique(in.bank_scales.begin(), in.bank_scales.end()),
                           in.bank_scales.end());
    }
  }
  BankScale chosen = ChooseBankScale(in);
  const double kept = RecordedScale(
      bank, bank.KeepMeta(kBankScaleMetaKey, fmt::format("{:.17g}", chosen.px_per_m)));
  if (kept != chosen.px_per_m) {
    // Another writer chose first, between our read and our write: its scale is the bank's.
    in.bank_scales = {kept};
    chosen = ChooseBankScale(in);
    chosen.why += " (recorded by another writer that started at the same time)";
  }
  return chosen;
}

}  // namespace ss
