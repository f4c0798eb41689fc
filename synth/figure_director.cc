// Figures on the stage: each follows its own seeded timeline of actions:
// idle, turn toward a spot, walk there, turn to the camera, Y M C A, rest, again.
#include <algorithm>
#include <cmath>
#include <string>

#include <nlohmann/json.hpp>

#include "core/error.h"
#include "synth/angles.h"
#include "synth/directors.h"
#include "synth/figure.h"
#include "synth/random.h"

namespace ss::synth {
namespace {

constexpr double kTurnRate = 2.2;     // rad/s
constexpr double kGestureIn = 0.45;   // s to reach an arm pose
constexpr double kGestureHold = 1.0;  // s held

class FigureActor {
 public:
  FigureActor(const FigureBuild& build, uint64_t seed, double lane_x, double lane_half,
              const Eigen::Vector2d& face, const Studio& studio)
      : build_(build),
        rng_(seed),
        lane_x_(lane_x),
        lane_half_(lane_half),
        face_(face),
        studio_(&studio) {
    state_.position = {lane_x + rng_.Uniform(-lane_half, lane_half) * 0.6, rng_.Uniform(-0.4, 0.8)};
    state_.heading_rad = std::atan2(face.y() - state_.position.y(), face.x() - state_.position.x());
    Plan();
  }

  void Step(double dt) {
    FigureState& s = state_;
    s.time_s += dt;
    left_s_ -= dt;
    const double speed_target = action_ == Action::kWalk ? 1.0 : 0.0;  // the same for both builds
    s.speed_mps += std::clamp(speed_target - s.speed_mps, -2.0 * dt, 2.0 * dt);
    switch (action_) {
      case Action::kIdle:
        s.pose = "idle";
        if (left_s_ <= 0) Next();
        break;
      case Action::kTurn: {
        s.pose = "turn";
        const double diff = Wrap(target_heading_ - s.heading_rad);
        const double step = std::clamp(diff, -kTurnRate * dt, kTurnRate * dt);
        s.heading_rad = Wrap(s.heading_rad + step);
        s.gait_phase += std::abs(step) * 0.25;
        if (std::abs(diff - step) < 1e-3) Next();
        break;
      }
      case Action::kWalk: {
        s.pose = "walk";
        const Eigen::Vector2d to = target_ - s.position;
        const double dist = to.norm();
        s.heading_rad = std::atan2(to.y(), to.x());
        const double move = std::min(dist, s.speed_mps * dt);
        if (dist > 1e-9) s.position += to / dist * move;
        if (dist < 0.35) s.speed_mps = std::min(s.speed_mps, std::max(0.15, dist * 2.0));
        if (dist < 1e-3) Next();
        break;
      }
      case Action::kGesture:
        s.blend = std::min(1.0, s.blend + dt / kGestureIn);
        s.pose = s.blend >= 0.5 ? ArmPoseName(s.to) : ArmPoseName(s.from);
        if (s.pose == "rest") s.pose = "idle";
        if (left_s_ <= 0) Next();
        break;
    }
    // One walk cycle (two steps) per 1.35 m at full height.
    s.gait_phase += s.speed_mps * dt / (1.35 * build_.height_m / 1.75);
    s.gait_phase -= std::floor(s.gait_phase);
    const double walk_target =
        std::min(1.0, s.speed_mps / 0.5) + (action_ == Action::kTurn ? 0.4 : 0.0);
    s.walking += std::clamp(std::min(1.0, walk_target) - s.walking, -3.0 * dt, 3.0 * dt);
  }

  const FigureState& state() const { return state_; }
  const FigureBuild& build() const { return build_; }

 private:
  enum class Action { kIdle, kTurn, kWalk, kGesture };
  struct Item {
    Action action;
    double seconds = 0;
    Eigen::Vector2d target = Eigen::Vector2d::Zero();
    ArmPose pose = ArmPose::kRest;
    bool face_camera = false;
  };

  // The next round: idle, turn and walk to a new spot, face the camera, Y M C A, rest.
  void Plan() {
    const Eigen::Vector2d spot(lane_x_ + rng_.Uniform(-lane_half_, lane_half_),
                               rng_.Uniform(-0.8, std::min(1.0, studio_->half_y - 0.5)));
    plan_.push_back({Action::kIdle, rng_.Uniform(0.8, 2.0)});
    plan_.push_back({Action::kTurn, 0, spot});
    plan_.push_back({Action::kWalk, 0, spot});
    plan_.push_back({Action::kTurn, 0, Eigen::Vector2d::Zero(), ArmPose::kRest, true});
    for (ArmPose p : {ArmPose::kY, ArmPose::kM, ArmPose::kC, ArmPose::kA}) {
      plan_.push_back(
          {Action::kGesture, kGestureIn + kGestureHold * rng_.Uniform(0.8, 1.3), {}, p});
    }
    plan_.push_back({Action::kGesture, kGestureIn + 0.2, {}, ArmPose::kRest});
    Next();
  }

  void Next() {
    if (plan_.empty()) {
      Plan();
      return;
    }
    const Item item = plan_.front();
    plan_.erase(plan_.begin());
    action_ = item.action;
    left_s_ = item.seconds;
    target_ = item.target;
    if (item.action == Action::kTurn) {
      const Eigen::Vector2d to =
          item.face_camera ? face_ - state_.position : item.target - state_.position;
      target_heading_ = to.norm() > 1e-6 ? std::atan2(to.y(), to.x()) : state_.heading_rad;
    }
    if (item.action == Action::kGesture) {
      state_.from = state_.blend >= 0.5 ? state_.to : state_.from;
      state_.to = item.pose;
      state_.blend = 0.0;
    }
  }

  FigureBuild build_;
  Rng rng_;
  double lane_x_, lane_half_;
  Eigen::Vector2d face_;
  const Studio* studio_;
  FigureState state_;
  std::vector<Item> plan_;
  Action action_ = Action::kIdle;
  double left_s_ = 0;
  Eigen::Vector2d target_ = Eigen::Vector2d::Zero();
  double target_heading_ = 0;
};

class FigureDirector : public Director {
 public:
  FigureDirector(const Studio& studio, const std::vector<SynthCamera>& cameras,
                 const DirectorOptions& options)
      : studio_(studio), options_(options) {
    const Eigen::Vector3d cam = cameras.front().CentreInGround();
    const int n = std::max(1, options.subjects);
    const double span = 2.0 * (studio.half_x - 0.6);
    for (int i = 0; i < options.subjects; ++i) {
      const double lane_half = 0.5 * span / n;
      const double lane_x = -0.5 * span + (2 * i + 1) * lane_half;
      // Alternate builds when several figures share a session.
      const int variant = (options.figure_variant + i) % 2;
      actors_.emplace_back(FigureBuildFor(variant),
                           StreamSeed(options.seed, "figure-timeline", static_cast<uint64_t>(i)),
                           lane_x, std::max(0.05, lane_half - 0.35), cam.head<2>(), studio);
      variants_.push_back(variant);
    }
  }

  int subjects() const override { return static_cast<int>(actors_.size()); }
  std::vector<std::string> joint_names() const override { return FigureJointNames(); }

  void Frame(double time_s, FrameSnapshot* out) override {
    const int slices = StartFrame(out, subjects(), options_.motion_blur);
    const double exposure = 0.5 / options_.fps;
    std::vector<std::vector<Eigen::Vector3d>> joints(actors_.size());
    for (int sl = slices - 1; sl >= 0; --sl) {
      AdvanceTo(time_s - exposure * sl / slices);
      for (size_t i = 0; i < actors_.size(); ++i) {
        const auto& a = actors_[i];
        joints[i] = FigureJoints(a.build(), a.state());
        auto prims =
            FigurePrimitives(a.build(), joints[i], a.state().heading_rad, static_cast<int>(i),
                             StreamSeed(options_.seed, "figure-look", i));
        for (auto& p : prims) p.slice = sl;
        out->scene.primitives.insert(out->scene.primitives.end(), prims.begin(), prims.end());
      }
    }
    for (size_t i = 0; i < actors_.size(); ++i) {
      // A figure touches a wall within 10 mm; any part beyond the floor leaves it.
      SubjectTruth t = TruthOf("figure", actors_[i].state(), studio_, out->scene.primitives,
                               static_cast<int>(i), 0.01, 0.0);
      t.joints = joints[i];
      out->subjects.push_back(std::move(t));
    }
  }

  std::string SubjectsJson() const override {
    nlohmann::json list = nlohmann::json::array();
    for (size_t i = 0; i < actors_.size(); ++i) {
      const FigureBuild& b = actors_[i].build();
      list.push_back({{"subject", i},
                      {"kind", "figure"},
                      {"variant", variants_[i]},
                      {"height_m", b.height_m},
                      {"shoulder_half_m", b.shoulder_half_m},
                      {"hip_half_m", b.hip_half_m},
                      {"hip_height_m", b.hip_height_m},
                      {"upper_arm_m", b.upper_arm_m},
                      {"forearm_m", b.forearm_m},
                      {"girth", b.girth}});
    }
    return list.dump();
  }

 private:
  void AdvanceTo(double t) {
    if (t <= now_) return;
    const double dt = t - now_;
    const int n = std::max(1, static_cast<int>(std::ceil(dt * 120.0 - 1e-9)));
    for (auto& a : actors_) {
      for (int k = 0; k < n; ++k) a.Step(dt / n);
    }
    now_ = t;
  }

  const Studio& studio_;
  DirectorOptions options_;
  std::vector<FigureActor> actors_;
  std::vector<int> variants_;
  double now_ = 0.0;
};

}  // namespace

std::unique_ptr<Director> MakeFigureDirector(const Studio& studio,
                                             const std::vector<SynthCamera>& cameras,
                                             const DirectorOptions& options) {
  if (std::string why; !options.IsValid(&why)) throw InputError("director options", why);
  if (studio.kind != StudioKind::kStage)
    throw InputError("kind", "figures perform on the stage studio");
  return std::make_unique<FigureDirector>(studio, cameras, options);
}

}  // namespace ss::synth
