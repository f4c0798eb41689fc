#include "pipeline/transitions/synthetic.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <random>

#include "core/error.h"
#include "core/option_checks.h"

namespace ss {

namespace {

constexpr double kWidthM = 0.22;  // billboard size (metres)
constexpr double kHeightM = 0.17;
constexpr int kSuper = 2;  // supersampling per axis

using Rgb = std::array<double, 3>;

// A supersampled canvas in metric billboard coordinates: x right (0 = centre), z up (0 = floor).
class Canvas {
 public:
  Canvas(double px_per_m) : scale_(px_per_m * kSuper) {
    width_px_ = static_cast<int>(std::ceil(kWidthM * px_per_m));
    height_px_ = static_cast<int>(std::ceil(kHeightM * px_per_m));
    w_ = width_px_ * kSuper;
    h_ = height_px_ * kSuper;
    rgb_.assign(static_cast<size_t>(w_) * h_, Rgb{0, 0, 0});
    covered_.assign(static_cast<size_t>(w_) * h_, 0);
  }
  // Paints every sample whose centre lies in the ellipse; colour may depend on (x, z).
  void Ellipse(double cx, double cz, double ax, double az,
               const std::function<Rgb(double, double)>& colour) {
    if (ax <= 0 || az <= 0) return;
    Span(
        cx - ax, cz - az, cx + ax, cz + az,
        [&](double x, double z) {
          const double u = (x - cx) / ax, v = (z - cz) / az;
          return u * u + v * v <= 1.0;
        },
        colour);
  }
  void Rect(double x0, double z0, double x1, double z1, const Rgb& colour) {
    Span(
        x0, z0, x1, z1, [](double, double) { return true; },
        [&](double, double) { return colour; });
  }
  RgbaBillboard Resolve(std::mt19937_64& rng, int noise) const {
    RgbaBillboard b;
    b.width = width_px_;
    b.height = height_px_;
    b.rgba.assign(static_cast<size_t>(b.width) * b.height * 4, 0);
    std::uniform_int_distribution<int> jitter(-noise, noise);
    for (int y = 0; y < b.height; ++y) {
      for (int x = 0; x < b.width; ++x) {
        int count = 0;
        Rgb sum{0, 0, 0};
        for (int sy = 0; sy < kSuper; ++sy) {
          for (int sx = 0; sx < kSuper; ++sx) {
            const size_t s = static_cast<size_t>(y * kSuper + sy) * w_ + (x * kSuper + sx);
            if (!covered_[s]) continue;
            ++count;
            for (int c = 0; c < 3; ++c) sum[c] += rgb_[s][c];
          }
        }
        if (count == 0) continue;
        uint8_t* p = b.rgba.data() + (static_cast<size_t>(y) * b.width + x) * 4;
        for (int c = 0; c < 3; ++c)
          p[c] =
              static_cast<uint8_t>(std::clamp(std::lround(sum[c] / count) + jitter(rng), 0L, 255L));
        p[3] = static_cast<uint8_t>(count * 255 / (kSuper * kSuper));
      }
    }
    // The anchor: the lowest row holding alpha >= 128, at its alpha-weighted mean column.
    b.anchor_y_px = b.height - 1;
    b.anchor_x_px = (b.width - 1) / 2.0;
    for (int y = b.height - 1; y >= 0; --y) {
      double sum = 0, weight = 0;
      for (int x = 0; x < b.width; ++x) {
        const uint8_t a = b.Pixel(x, y)[3];
        if (a >= 128) {
          sum += a * x;
          weight += a;
        }
      }
      if (weight > 0) {
        b.anchor_y_px = y;
        b.anchor_x_px = sum / weight;
        break;
      }
    }
    return b;
  }

 private:
  void Span(double x0, double z0, double x1, double z1,
            const std::function<bool(double, double)>& inside,
            const std::function<Rgb(double, double)>& colour) {
    const int sx0 = std::max(0, static_cast<int>(std::floor((x0 + kWidthM / 2) * scale_)));
    const int sx1 = std::min(w_ - 1, static_cast<int>(std::ceil((x1 + kWidthM / 2) * scale_)));
    const int sy0 = std::max(0, static_cast<int>(std::floor((kHeightM - z1) * scale_)));
    const int sy1 = std::min(h_ - 1, static_cast<int>(std::ceil((kHeightM - z0) * scale_)));
    for (int sy = sy0; sy <= sy1; ++sy) {
      const double z = kHeightM - (sy + 0.5) / scale_;
      if (z < z0 || z > z1) continue;
      for (int sx = sx0; sx <= sx1; ++sx) {
        const double x = (sx + 0.5) / scale_ - kWidthM / 2;
        if (x < x0 || x > x1 || !inside(x, z)) continue;
        const size_t s = static_cast<size_t>(sy) * w_ + sx;
        rgb_[s] = colour(x, z);
        covered_[s] = 1;
      }
    }
  }

  double scale_;
  int width_px_, height_px_, w_, h_;
  std::vector<Rgb> rgb_;
  std::vector<uint8_t> covered_;
};

Rgb Shade(const Rgb& c, double brightness) {
  return {c[0] * brightness, c[1] * brightness, c[2] * brightness};
}

struct State {
  std::string pose = "walk";
  double heading = 0;    // radians; the camera looks along +y, so sin(heading) < 0 faces it
  double turn_rate = 0;  // radians per frame
  double speed = 0.08;   // m/s
  double phase = 0;      // cycles of the pose's motion: the gait, the idle sniff, the standing sway
  double brightness = 1;
  double size = 1;
};

// Where the animal's parts are in state `s`, in the billboard plane: x right (0 = the body
// centre), z up (0 = the floor), metres; `depth` orders the painting (larger = farther).
struct Geometry {
  struct Leg {
    double x, lift, depth;
  };
  double body_z = 0, body_ax = 0, body_az = 0;
  double head_x = 0, head_z = 0, head_depth = 0;
  std::vector<Leg> legs;  // walk/trot: 4, stand: the hind pair, idle: none
};

Geometry Layout(const State& s) {
  Geometry g;
  const double c = std::cos(s.heading), sn = std::sin(s.heading), k = s.size;
  const bool gait = s.pose == "walk" || s.pose == "trot";
  const double stretch =
      gait ? (s.pose == "trot" ? 0.12 : 0.06) * std::sin(4 * M_PI * s.phase) : 0.0;
  double head_f;
  if (s.pose == "stand") {
    // Standing up, swaying: the head circles once per cycle.
    const double a = 2 * M_PI * s.phase;
    g.body_z = 0.07 * k;
    g.body_ax = k * 0.035 * (0.75 + 0.25 * std::abs(c));
    g.body_az = 0.06 * k;
    head_f = 0.012 * k + 0.012 * k * std::sin(a);
    g.head_z = 0.135 * k + 0.006 * k * std::cos(a);
  } else {
    const double length = 0.13 * k * (1 + stretch), width = 0.075 * k;
    const double height = (s.pose == "idle" ? 0.072 : 0.065) * k * (1 - 0.5 * stretch);
    g.body_z = (s.pose == "idle" ? 0.038 : 0.05) * k;
    g.body_ax = std::sqrt(std::pow(0.5 * length * c, 2) + std::pow(0.5 * width * sn, 2));
    g.body_az = 0.5 * height;
    // Idle: sniffing, the head circles once per cycle.
    const double a = 2 * M_PI * s.phase;
    const bool idle = s.pose == "idle";
    head_f = 0.5 * length * 0.85 + (idle ? 0.008 * k * std::cos(a) : 0.0);
    g.head_z = g.body_z + 0.012 * k + (idle ? 0.007 * k * std::sin(a) : 0.0);
  }
  g.head_x = head_f * c;
  g.head_depth = head_f * sn - 1e-4;
  // Legs (walk and trot swing them; idle hides them; stand shows the hind pair).
  if (s.pose != "idle") {
    struct LegSpec {
      double forward, lateral, offset;
    };
    const bool trot = s.pose == "trot";
    const std::array<LegSpec, 4> specs = {LegSpec{0.04, 0.025, 0.0}, LegSpec{0.04, -0.025, 0.5},
                                          LegSpec{-0.04, 0.025, trot ? 0.5 : 0.75},
                                          LegSpec{-0.04, -0.025, trot ? 0.0 : 0.25}};
    for (const LegSpec& l : specs) {
      if (s.pose == "stand" && l.forward > 0) continue;
      double f = l.forward * k, lift = 0;
      if (gait) {
        const double a = 2 * M_PI * (s.phase + l.offset);
        f += (trot ? 0.022 : 0.015) * k * std::sin(a);
        lift = 0.007 * k * std::max(0.0, std::cos(a));
      }
      if (s.pose == "stand") f = 0.0;
      g.legs.push_back({f * c - l.lateral * k * sn, lift, f * sn + l.lateral * k * c});
    }
  }
  return g;
}

// The shapes each part paints, in the billboard plane (metres), shared by the renderer and
// the key points' visibility so that both see the same picture.
struct EllipseShape {
  double cx, cz, ax, az;
  bool Contains(double x, double z) const {
    if (ax <= 0 || az <= 0) return false;
    const double u = (x - cx) / ax, v = (z - cz) / az;
    return u * u + v * v <= 1.0;
  }
};
struct RectShape {
  double x0, z0, x1, z1;
  bool Contains(double x, double z) const { return x >= x0 && x <= x1 && z >= z0 && z <= z1; }
};
enum class HeadPiece { kHead, kEar, kFace, kEye };

RectShape LegShape(const Geometry& g, const Geometry::Leg& l, double k) {
  const double top = g.body_z - g.body_az + 0.012 * k;
  return {l.x - 0.006 * k, l.lift, l.x + 0.006 * k, top};
}
EllipseShape BodyShape(const Geometry& g) { return {0, g.body_z, g.body_ax, g.body_az}; }
// The head's pieces in painting order: the head, both ears, the face (when it is toward the
// camera), the eye.
std::vector<std::pair<HeadPiece, EllipseShape>> HeadShapes(const Geometry& g, const State& s) {
  const double c = std::cos(s.heading), sn = std::sin(s.heading), k = s.size;
  const double head_x = g.head_x, head_z = g.head_z, r = 0.028 * k;
  const bool facing = sn < 0;  // the face is toward the camera
  std::vector<std::pair<HeadPiece, EllipseShape>> out;
  out.push_back({HeadPiece::kHead, {head_x, head_z, r, r * 0.95}});
  for (int side : {-1, 1}) {
    const double ex = head_x + side * 0.012 * k * std::abs(sn) - 0.006 * k * c;
    out.push_back({HeadPiece::kEar, {ex, head_z + 0.85 * r, 0.009 * k, 0.009 * k}});
  }
  if (facing) {
    out.push_back({HeadPiece::kFace,
                   {head_x + 0.5 * r * c, head_z - 0.25 * r, 0.6 * r * (0.4 + 0.6 * std::abs(sn)),
                    0.45 * r}});
  }
  const double eye_x = head_x + 0.45 * r * c;
  if (facing || std::abs(c) > 0.3) {
    out.push_back({HeadPiece::kEye, {eye_x, head_z + 0.2 * r, 0.0045 * k, 0.0045 * k}});
  }
  return out;
}

// The parts in Render's painting order, farthest first: part l < legs is leg l, part legs
// is the body, part legs + 1 the head.
std::vector<int> PaintOrder(const Geometry& g) {
  const int legs = static_cast<int>(g.legs.size());
  std::vector<std::pair<double, int>> parts;
  parts.reserve(legs + 2);  // the legs, the body and the head
  for (int l = 0; l < legs; ++l) parts.push_back({g.legs[l].depth, l});
  parts.push_back({0.0, legs});
  parts.push_back({g.head_depth, legs + 1});
  std::stable_sort(parts.begin(), parts.end(),
                   [](const auto& a, const auto& b) { return a.first > b.first; });
  std::vector<int> order;
  order.reserve(parts.size());
  for (const auto& p : parts) order.push_back(p.second);
  return order;
}

// The key points of state `s` (billboard plane, metres, fixed order per pose): head centre,
// the body's right and left extremes and top, each leg's foot. `visible` gets, per point,
// whether the picture shows it: a point is hidden when a part painted after its own part
// (nearer the camera) covers it — the head centre behind the body, the body top or an
// extreme behind the head, a foot behind a nearer leg.
std::vector<double> Keypoints(const State& s, std::vector<uint8_t>* visible) {
  const Geometry g = Layout(s);
  std::vector<double> p = {g.head_x,   g.head_z, g.body_ax, g.body_z,
                           -g.body_ax, g.body_z, 0.0,       g.body_z + g.body_az};
  for (const Geometry::Leg& l : g.legs) {
    p.push_back(l.x);
    p.push_back(l.lift);
  }
  const int legs = static_cast<int>(g.legs.size()), body = legs, head = legs + 1;
  std::vector<int> owner = {head, body, body, body};
  for (int l = 0; l < legs; ++l) owner.push_back(l);
  const std::vector<int> order = PaintOrder(g);
  std::vector<size_t> rank(order.size());
  for (size_t r = 0; r < order.size(); ++r) rank[order[r]] = r;
  const auto head_shapes = HeadShapes(g, s);
  auto covers = [&](int part, double x, double z) {
    if (part == head) {
      return std::any_of(head_shapes.begin(), head_shapes.end(),
                         [&](const auto& piece) { return piece.second.Contains(x, z); });
    }
    if (part == body) return BodyShape(g).Contains(x, z);
    return LegShape(g, g.legs[part], s.size).Contains(x, z);
  };
  visible->assign(owner.size(), 1);
  for (size_t k = 0; k < owner.size(); ++k) {
    for (size_t r = rank[owner[k]] + 1; r < order.size(); ++r) {
      if (covers(order[r], p[2 * k], p[2 * k + 1])) {
        (*visible)[k] = 0;
        break;
      }
    }
  }
  return p;
}

// The original's key point that point k of its mirror image is the image of: the head and
// the body top keep their places, the body's right and left extremes swap, and so do the
// feet of legs 0 and 1 and of legs 2 and 3 (the mirrored state's gait phase is p + 0.5; a
// standing pose shows legs 2 and 3 only).
size_t MirrorKeypoint(size_t k) {
  if (k == 1 || k == 2) return 3 - k;
  if (k < 4) return k;
  return 4 + ((k - 4) ^ 1);
}

// Renders the animal in state `s`.
RgbaBillboard Render(const State& s, double px_per_m, std::mt19937_64& rng, int noise) {
  Canvas canvas(px_per_m);
  const Geometry g = Layout(s);
  const double k = s.size;
  const Rgb fur = Shade({205, 150, 85}, s.brightness), belly = Shade({236, 214, 176}, s.brightness);
  const Rgb stripe = Shade({150, 100, 58}, s.brightness), leg = Shade({170, 120, 80}, s.brightness);
  const Rgb face = Shade({240, 222, 192}, s.brightness), ear = Shade({215, 140, 130}, s.brightness);
  const Rgb eye{25, 20, 20};

  std::vector<std::function<void()>> parts;  // by part index (PaintOrder)
  const double body_z = g.body_z;
  for (const Geometry::Leg& l : g.legs) {
    const RectShape r = LegShape(g, l, k);
    parts.push_back([&canvas, r, leg] { canvas.Rect(r.x0, r.z0, r.x1, r.z1, leg); });
  }
  const EllipseShape body_shape = BodyShape(g);
  parts.push_back([&canvas, body_shape, body_z, fur, belly, stripe] {
    const double body_az = body_shape.az;
    canvas.Ellipse(body_shape.cx, body_shape.cz, body_shape.ax, body_shape.az,
                   [=](double, double z) {
                     if (z < body_z - 0.45 * body_az) return belly;
                     if (z > body_z + 0.7 * body_az) return stripe;
                     return fur;
                   });
  });
  const auto head_shapes = HeadShapes(g, s);
  parts.push_back([=, &canvas] {
    for (const auto& [piece, e] : head_shapes) {
      const Rgb colour = piece == HeadPiece::kHead   ? fur
                         : piece == HeadPiece::kEar  ? ear
                         : piece == HeadPiece::kFace ? face
                                                     : eye;
      canvas.Ellipse(e.cx, e.cz, e.ax, e.az, [=](double, double) { return colour; });
    }
  });
  for (int part : PaintOrder(g)) parts[part]();
  return canvas.Resolve(rng, noise);
}

const char* PickPose(std::mt19937_64& rng) {
  const double u = std::uniform_real_distribution<double>(0, 1)(rng);
  if (u < 0.50) return "walk";
  if (u < 0.75) return "trot";
  if (u < 0.90) return "idle";
  return "stand";
}

double PoseSpeed(const std::string& pose) {
  if (pose == "walk") return 0.08;
  if (pose == "trot") return 0.22;
  return 0.0;
}

}  // namespace

bool SyntheticSpriteOptions::IsValid(std::string* why) const {
  OptionProblems check(why);
  check.Within(frames, AtLeast(0), "frames", "a number >= 0");
  for (const auto& [v, field] : {std::pair{px_per_m, "px_per_m"}, std::pair{fps, "fps"}}) {
    check(std::isfinite(v) && v > 0, field,
          "expected a positive number, got " + OptionProblems::Num(v));
  }
  // A clip of 0 frames would never end the clip loop.
  check.Within(min_clip_frames, AtLeast(1), "min_clip_frames", "at least 1 frame");
  check(max_clip_frames >= min_clip_frames, "max_clip_frames",
        "expected at least min_clip_frames (" + std::to_string(min_clip_frames) + "), got " +
            std::to_string(max_clip_frames));
  check.Within(velocity_noise_mps, AtLeast(0), "velocity_noise_mps", "a number >= 0");
  check.Within(pixel_noise, Between(0, 255), "pixel_noise", "0 to 255 levels");
  return check.ok();
}

std::vector<SyntheticSprite> MakeSyntheticSprites(const SyntheticSpriteOptions& o) {
  if (std::string why; !o.IsValid(&why)) throw InputError("synthetic sprite options", why);
  std::mt19937_64 rng(o.seed);
  std::normal_distribution<double> normal(0.0, 1.0);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  std::vector<SyntheticSprite> out;
  out.reserve(o.mirrors ? 2 * o.frames : o.frames);
  std::vector<std::pair<int64_t, int64_t>> clip_ranges;  // [first, last] indices in out
  std::vector<State> states;                             // of the originals, by index in out
  int64_t clip = 0;
  while (static_cast<int>(out.size()) < o.frames) {
    ++clip;
    const int length =
        std::min(o.frames - static_cast<int>(out.size()),
                 std::uniform_int_distribution<int>(o.min_clip_frames, o.max_clip_frames)(rng));
    State s;
    s.pose = PickPose(rng);
    s.heading = uniform(rng) * 2 * M_PI;
    s.speed = PoseSpeed(s.pose) * (0.8 + 0.4 * uniform(rng));
    s.phase = uniform(rng);
    s.brightness = 0.97 + 0.06 * uniform(rng);  // diffuse light from above: nearly constant
    s.size = 0.96 + 0.08 * uniform(rng);
    const int64_t first = static_cast<int64_t>(out.size());
    for (int f = 0; f < length; ++f) {
      if (f > 0) {  // one step of the random walk
        if (uniform(rng) < 0.01) s.pose = PickPose(rng);
        const bool gait = s.pose == "walk" || s.pose == "trot";
        const double max_turn = (gait ? 5.0 : 1.5) * M_PI / 180;
        s.turn_rate = std::clamp(s.turn_rate + normal(rng) * 0.6 * M_PI / 180, -max_turn, max_turn);
        s.heading = std::remainder(s.heading + s.turn_rate, 2 * M_PI);
        const double target = PoseSpeed(s.pose);
        s.speed = std::max(0.0, s.speed + 0.1 * (target - s.speed) + 0.004 * normal(rng));
        const double hz =
            gait ? s.speed / (s.pose == "trot" ? 0.10 : 0.07) : (s.pose == "idle" ? 0.7 : 0.4);
        s.phase = std::fmod(s.phase + hz / o.fps, 1.0);
        s.brightness = std::clamp(s.brightness + 0.001 * normal(rng), 0.95, 1.05);
      }
      const bool gait = s.pose == "walk" || s.pose == "trot";
      SyntheticSprite sprite;
      sprite.id = static_cast<int64_t>(out.size()) + 1;
      sprite.clip = clip;
      sprite.billboard = Render(s, o.px_per_m, rng, o.pixel_noise);
      sprite.cheap = DescribeBillboard(sprite.billboard, o.px_per_m);
      const double moving = gait ? s.speed : 0.0;
      sprite.speed_mps = moving;
      sprite.cheap.velocity_x_mps =
          moving * std::cos(s.heading) + o.velocity_noise_mps * normal(rng);
      sprite.cheap.velocity_y_mps =
          moving * std::sin(s.heading) + o.velocity_noise_mps * normal(rng);
      sprite.truth.pose = s.pose;
      sprite.truth.heading_rad = s.heading;
      sprite.truth.gait_phase = s.phase;
      sprite.truth.keypoints_m = Keypoints(s, &sprite.truth.keypoint_visible);
      sprite.truth.unordered_from = 4;  // the feet: which leg is which does not show
      states.push_back(s);
      out.push_back(std::move(sprite));
    }
    clip_ranges.emplace_back(first, static_cast<int64_t>(out.size()) - 1);
  }
  if (o.mirrors) {
    // Mirror x: heading theta -> pi - theta, vx -> -vx; the gait's left and right legs swap,
    // which is the same picture half a cycle later (the sniff and the sway are symmetric).
    for (const auto& [first, last] : clip_ranges) {
      ++clip;
      for (int64_t k = first; k <= last; ++k) {
        const SyntheticSprite& src = out[k];
        SyntheticSprite m;
        m.id = static_cast<int64_t>(out.size()) + 1;
        m.clip = clip;
        m.billboard = MirrorBillboard(src.billboard);
        m.cheap = src.cheap;
        m.cheap.velocity_x_mps = -src.cheap.velocity_x_mps;
        m.speed_mps = src.speed_mps;
        m.truth = src.truth;
        m.truth.heading_rad = std::remainder(M_PI - src.truth.heading_rad, 2 * M_PI);
        if (m.truth.pose == "walk" || m.truth.pose == "trot") {
          m.truth.gait_phase = std::fmod(m.truth.gait_phase + 0.5, 1.0);
        }
        // The mirror image is the picture of the mirrored state (legs swap as noted above):
        // its key points come from that state, so the legs keep their identities.
        State mirrored = states[k];
        mirrored.heading = m.truth.heading_rad;
        mirrored.phase = m.truth.gait_phase;
        std::vector<uint8_t> unused;
        m.truth.keypoints_m = Keypoints(mirrored, &unused);
        // Visibility is the picture's, i.e. the original's: the mirrored state's own painting
        // order can differ (its legs' depths are not the mirrored ones). Point k of the mirror
        // is the image of the original's point MirrorKeypoint(k).
        m.truth.keypoint_visible.resize(src.truth.keypoint_visible.size());
        for (size_t q = 0; q < m.truth.keypoint_visible.size(); ++q) {
          m.truth.keypoint_visible[q] = src.truth.keypoint_visible[MirrorKeypoint(q)];
        }
        out.push_back(std::move(m));
      }
    }
  }
  return out;
}

std::vector<SpriteInput> AsSpriteInputs(const std::vector<SyntheticSprite>& sprites) {
  std::vector<SpriteInput> inputs;
  inputs.reserve(sprites.size());
  for (const SyntheticSprite& s : sprites) inputs.push_back({s.id, s.clip, s.cheap, &s.billboard});
  return inputs;
}

}  // namespace ss
