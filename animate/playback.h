#pragma once
// Plays sequences back through the renderer: loads each shown sprite's billboard from its
// bank (a small cache keeps the recent ones) and renders one step at a time.
#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "animate/renderer.h"
#include "animate/sequence_io.h"
#include "core/bank.h"

namespace ss {

class SequencePlayer {
 public:
  // Opens the banks; `renderer` draws the frames.
  SequencePlayer(const std::vector<std::string>& bank_paths,
                 std::unique_ptr<SpriteRenderer> renderer);

  // The frame of step t (sprites past their end hold their last state).
  cv::Mat RenderStep(const std::vector<SpriteSequence>& sprites, int t);
  const SpriteRenderer& renderer() const { return *renderer_; }

 private:
  struct Billboard {
    SpritePixels pixels;
    Eigen::Vector2d anchor_px;
    double px_per_m = 0;
    SpriteKind kind = SpriteKind::kUpright;
    double heading_rad = 0;
  };
  const Billboard& Load(const BankFrameRef& ref);

  std::vector<std::unique_ptr<Bank>> banks_;
  std::unique_ptr<SpriteRenderer> renderer_;
  std::map<std::pair<int, int64_t>, Billboard> cache_;
};

}  // namespace ss
