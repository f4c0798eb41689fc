#pragma once
// Banks the tests make: sprites with every field distinct, batches of originals
// and mirrors, a registered session and camera, a small sound bank, and raw
// SQLite access to damage one on purpose.
#include <cstdint>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "core/bank.h"

namespace ss::testing {

// A billboard with a soft elliptical matte, textured colour and a shadow blob.
SpritePixels MakePixels(int w, int h, uint32_t seed);
// An original sprite with every field distinct and derived from (frame, track).
SpriteRecord MakeSprite(int64_t frame, int64_t track, int w = 32, int h = 48);
// The mirrored copy of `o`.
SpriteRecord MakeMirror(const SpriteRecord& o);
// Originals and mirrors for frames [first, last] of one track.
std::vector<SpriteRecord> MakeBatch(int64_t first, int64_t last, int64_t track,
                                    bool mirrors = true);

struct Fixture {
  int64_t session = 0, camera = 0;
};
// One session with one camera.
Fixture Register(BankWriter& w);
ClipRecord Clip(int64_t camera, int64_t track, int64_t first, bool complete);
// A small sound bank (one complete clip of 6 frames, one open clip); the id of one original.
int64_t SmallBank(const std::string& path);

// Straight SQLite, bypassing the bank's code: a count, and a statement (to damage a bank).
int64_t RawCount(const std::string& path, const std::string& sql);
void RawExec(const std::string& path, const std::string& sql);
bool SameMat(const cv::Mat& a, const cv::Mat& b);

}  // namespace ss::testing
