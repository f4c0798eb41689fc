// The transition graph read from a sprite bank.
#include "animate/bank_graph.h"

#include <gtest/gtest.h>

#include <atomic>
#include <string>

#include "animate_test_bank.h"
#include "core/error.h"
#include "tests/support/test_support.h"

namespace ss {
namespace {

using testing::WalkerBank;

TEST(BankGraph, FramesSuccessorsTransitionsVelocitiesAndTags) {
  testing::ScratchDir dir;
  const WalkerBank bank = WalkerBank::Write(dir / "walker.ssbank");
  const BankGraph g = LoadBankGraph({dir / "walker.ssbank"}, {"standing"});
  const int n = 8 * WalkerBank::kClipFrames + WalkerBank::kStandFrames;
  ASSERT_EQ(g.graph.num_frames(), n);
  ASSERT_EQ(g.frames.size(), static_cast<size_t>(n));
  ASSERT_EQ(g.frame_interval_s.size(), 1u);
  EXPECT_NEAR(g.frame_interval_s[0], 1.0 / 30, 1e-6);
  auto frame = [&](int c, int m) { return g.FrameOf(0, bank.sprite_ids[c][m]); };
  for (int c = 0; c < 9; ++c) {
    const int len = c == 8 ? WalkerBank::kStandFrames : WalkerBank::kClipFrames;
    for (int m = 0; m < len; ++m) {
      const int i = frame(c, m);
      ASSERT_GE(i, 0);
      // Displacement per step = velocity x the source frame interval (1.5 m/s / 30 = 5 cm).
      EXPECT_NEAR(g.graph.speed_m(i), c == 8 ? 0.0 : 0.05, 1e-6);  // features are floats
      EXPECT_EQ(g.graph.HasTag(i, "standing"), c == 8);
      if (m + 1 < len) {
        EXPECT_TRUE(g.graph.IsNaturalSuccessor(i, frame(c, m + 1)));
        EXPECT_EQ(g.graph.EdgeCost(i, frame(c, m + 1)), 0.0);
      }
    }
  }
  // Clips do not run into each other; the bank's transitions keep their costs.
  EXPECT_FALSE(g.graph.HasEdge(frame(0, WalkerBank::kClipFrames - 1), frame(1, 0)));
  EXPECT_EQ(g.graph.EdgeCost(frame(0, WalkerBank::kClipFrames - 1), frame(0, 0)), 0.05);
  EXPECT_EQ(g.graph.EdgeCost(frame(3, 4), frame(4, 5)), 0.3);
  EXPECT_EQ(g.graph.EdgeCost(frame(3, 12), frame(8, 0)), 0.4);
  // 9 clips' natural successors + 8 * (1 + 12 + 2) + 1 transitions.
  EXPECT_EQ(g.graph.num_edges(), (n - 9) + 8 * 15 + 1);
}

TEST(BankGraph, TwoBanksArePooledWithoutEdgesBetweenThem) {
  testing::ScratchDir dir;
  WalkerBank::Write(dir / "a.ssbank");
  WalkerBank::Write(dir / "b.ssbank");
  const BankGraph g = LoadBankGraph({dir / "a.ssbank", dir / "b.ssbank"}, {});
  const int n = 8 * WalkerBank::kClipFrames + WalkerBank::kStandFrames;
  ASSERT_EQ(g.graph.num_frames(), 2 * n);
  EXPECT_EQ(g.frames[n].bank, 1);
  for (int i = 0; i < n; ++i) {
    for (int j : g.graph.successors(i)) EXPECT_LT(j, n);
  }
  EXPECT_THROW(LoadBankGraph({dir / "missing.ssbank"}, {}), InputError);
  // A cancel from another thread (a studio job's) stops the load between its reads.
  const std::atomic<bool> cancel{true};
  try {
    LoadBankGraph({dir / "a.ssbank"}, {}, &cancel);
    ADD_FAILURE() << "a cancelled load returned";
  } catch (const WorkError& e) {
    EXPECT_EQ(std::string(e.what()), dir / "a.ssbank" + ": cancelled");
  }
}

}  // namespace
}  // namespace ss
