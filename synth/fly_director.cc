// Flies in the enclosure: one FlyBehaviour per subject, stepped frame by frame.
#include <nlohmann/json.hpp>

#include "core/error.h"
#include "synth/directors.h"
#include "synth/fly.h"
#include "synth/random.h"

namespace ss::synth {
namespace {

class FlyDirector : public Director {
 public:
  FlyDirector(const Studio& studio, const DirectorOptions& options)
      : studio_(studio), options_(options) {
    Rng rng(StreamSeed(options.seed, "fly-placement"));
    std::vector<Eigen::Vector2d> placed;
    for (int i = 0; i < options.subjects; ++i) {
      const FlyLook look = RandomFlyLook(StreamSeed(options.seed, "fly", static_cast<uint64_t>(i)));
      // Starting places at least 0.1 m apart, away from the walls.
      const Eigen::Vector2d p = PlaceApart(studio, rng, placed, 0.08, 0.1);
      placed.push_back(p);
      flies_.emplace_back(studio, look,
                          StreamSeed(options.seed, "fly-behaviour", static_cast<uint64_t>(i)), p,
                          rng.Uniform(-M_PI, M_PI));
    }
  }

  int subjects() const override { return static_cast<int>(flies_.size()); }

  void Frame(double time_s, FrameSnapshot* out) override {
    const int slices = StartFrame(out, subjects(), options_.motion_blur);
    const double exposure = 0.5 / options_.fps;
    for (int s = slices - 1; s >= 0; --s) {  // slice 0 (truth, shadows) is the frame time
      AdvanceTo(time_s - exposure * s / slices);
      for (size_t i = 0; i < flies_.size(); ++i) {
        auto prims = FlyPrimitives(flies_[i].look(), flies_[i].state(), static_cast<int>(i), s);
        out->scene.primitives.insert(out->scene.primitives.end(), prims.begin(), prims.end());
      }
    }
    for (size_t i = 0; i < flies_.size(); ++i) {
      out->subjects.push_back(TruthOf("fly", flies_[i].state(), studio_, out->scene.primitives,
                                      static_cast<int>(i), kWallTouchM, kWallTouchM));
    }
  }

  std::string SubjectsJson() const override {
    nlohmann::json list = nlohmann::json::array();
    for (size_t i = 0; i < flies_.size(); ++i) {
      const FlyLook& l = flies_[i].look();
      list.push_back({{"subject", i},
                      {"kind", "fly"},
                      {"scale", l.scale},
                      {"length_m", kFlyLengthM * l.scale},
                      {"body_bgr", {l.body.x(), l.body.y(), l.body.z()}}});
    }
    return list.dump();
  }

 private:
  void AdvanceTo(double t) {
    if (t <= now_) return;
    std::vector<Eigen::Vector2d> roots;
    for (const auto& f : flies_) roots.push_back(f.state().position);
    for (size_t i = 0; i < flies_.size(); ++i) {
      std::vector<Eigen::Vector2d> others;
      for (size_t j = 0; j < roots.size(); ++j) {
        if (j != i) others.push_back(roots[j]);
      }
      flies_[i].Step(t - now_, others);
    }
    now_ = t;
  }

  const Studio& studio_;
  DirectorOptions options_;
  std::vector<FlyBehaviour> flies_;
  double now_ = 0.0;
};

}  // namespace

std::unique_ptr<Director> MakeFlyDirector(const Studio& studio, const DirectorOptions& options) {
  if (std::string why; !options.IsValid(&why)) throw InputError("director options", why);
  if (studio.kind != StudioKind::kEnclosure)
    throw InputError("kind", "flies live in the enclosure studio");
  return std::make_unique<FlyDirector>(studio, options);
}

}  // namespace ss::synth
