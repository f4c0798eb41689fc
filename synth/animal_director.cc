// Animals in the enclosure: one AnimalBehaviour per subject, stepped frame by frame.
#include <algorithm>
#include <cmath>
#include <string>

#include <nlohmann/json.hpp>

#include "core/error.h"
#include "synth/animal.h"
#include "synth/directors.h"
#include "synth/random.h"

namespace ss::synth {
namespace {

class AnimalDirector : public Director {
 public:
  AnimalDirector(const Studio& studio, const std::vector<SynthCamera>& cameras,
                 const DirectorOptions& options)
      : studio_(studio), options_(options) {
    std::vector<Eigen::Vector3d> centres;
    centres.reserve(cameras.size());
    for (const auto& c : cameras) centres.push_back(c.CentreInGround());
    Rng rng(StreamSeed(options.seed, "animal-placement"));
    std::vector<Eigen::Vector2d> placed;
    for (int i = 0; i < options.subjects; ++i) {
      const AnimalLook look =
          RandomAnimalLook(StreamSeed(options.seed, "animal", static_cast<uint64_t>(i)));
      // Starting places at least 0.2 m apart, away from the walls.
      const Eigen::Vector2d p = PlaceApart(studio, rng, placed, 0.16, 0.2);
      placed.push_back(p);
      animals_.emplace_back(studio, look,
                            StreamSeed(options.seed, "animal-behaviour", static_cast<uint64_t>(i)),
                            p, rng.Uniform(-M_PI, M_PI), centres);
    }
  }

  int subjects() const override { return static_cast<int>(animals_.size()); }

  void Frame(double time_s, FrameSnapshot* out) override {
    const int slices = StartFrame(out, subjects(), options_.motion_blur);
    const double exposure = 0.5 / options_.fps;
    // Slice s is the body at time_s - exposure * (slices - 1 - s) / slices; slice
    // 0 (used for shadows and truth) must be the frame time, so slices are ordered last first.
    for (int s = slices - 1; s >= 0; --s) {
      const double t = time_s - exposure * s / slices;
      AdvanceTo(t);
      for (size_t i = 0; i < animals_.size(); ++i) {
        auto prims =
            AnimalPrimitives(animals_[i].look(), animals_[i].state(), static_cast<int>(i), s);
        out->scene.primitives.insert(out->scene.primitives.end(), prims.begin(), prims.end());
      }
    }
    for (size_t i = 0; i < animals_.size(); ++i) {
      out->subjects.push_back(TruthOf("animal", animals_[i].state(), studio_, out->scene.primitives,
                                      static_cast<int>(i), kWallTouchM, kWallTouchM));
    }
  }

  std::string SubjectsJson() const override {
    nlohmann::json list = nlohmann::json::array();
    for (size_t i = 0; i < animals_.size(); ++i) {
      const AnimalLook& l = animals_[i].look();
      list.push_back({{"subject", i},
                      {"kind", "animal"},
                      {"scale", l.scale},
                      {"length_m", 0.19 * l.scale},
                      {"fur_bgr", {l.fur.x(), l.fur.y(), l.fur.z()}},
                      {"belly_bgr", {l.belly.x(), l.belly.y(), l.belly.z()}}});
    }
    return list.dump();
  }

 private:
  void AdvanceTo(double t) {
    if (t <= now_) return;
    const double dt = t - now_;
    std::vector<Eigen::Vector2d> roots;
    for (const auto& a : animals_) roots.push_back(a.state().position);
    for (size_t i = 0; i < animals_.size(); ++i) {
      std::vector<Eigen::Vector2d> others;
      for (size_t j = 0; j < roots.size() && !options_.crossing; ++j) {
        if (j != i) others.push_back(roots[j]);
      }
      // --crossing: each heads for the next animal instead of keeping apart.
      const Eigen::Vector2d* seek =
          options_.crossing && roots.size() > 1 ? &roots[(i + 1) % roots.size()] : nullptr;
      animals_[i].Step(dt, others, seek);
    }
    now_ = t;
  }

  const Studio& studio_;
  DirectorOptions options_;
  std::vector<AnimalBehaviour> animals_;
  double now_ = 0.0;
};

}  // namespace

std::unique_ptr<Director> MakeAnimalDirector(const Studio& studio,
                                             const std::vector<SynthCamera>& cameras,
                                             const DirectorOptions& options) {
  if (std::string why; !options.IsValid(&why)) throw InputError("director options", why);
  if (studio.kind != StudioKind::kEnclosure)
    throw InputError("kind", "animals live in the enclosure studio");
  return std::make_unique<AnimalDirector>(studio, cameras, options);
}

}  // namespace ss::synth
