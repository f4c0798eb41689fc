#include "animate/transition_graph.h"

#include <cmath>

#include <gtest/gtest.h>

#include "animate/sequence_io.h"
#include "animate/track.h"
#include "core/error.h"
#include "tests/support/test_support.h"

namespace ss {
namespace {

using testing::ScratchDir;

std::vector<FrameInfo> TwoClips() {
  std::vector<FrameInfo> frames(5);
  frames[0].clip = frames[1].clip = frames[2].clip = 7;
  frames[3].clip = frames[4].clip = 9;
  frames[3].tags = {"standing"};
  return frames;
}

TEST(TransitionGraph, NaturalSuccessorsAndTransitionsInBothDirections) {
  const TransitionGraph graph(TwoClips(), {{2, 3, 0.5}, {4, 0, 1.25}, {2, 3, 0.25}, {1, 1, 0.1}});
  EXPECT_EQ(graph.num_frames(), 5);
  // 0->1, 1->2, 3->4 natural; 2->3 (cheapest kept), 4->0, 1->1.
  EXPECT_EQ(graph.num_edges(), 6);
  EXPECT_DOUBLE_EQ(*graph.EdgeCost(0, 1), 0.0);
  EXPECT_DOUBLE_EQ(*graph.EdgeCost(2, 3), 0.25);
  EXPECT_DOUBLE_EQ(*graph.EdgeCost(4, 0), 1.25);
  EXPECT_FALSE(graph.HasEdge(2, 4));  // no natural edge across clips
  EXPECT_FALSE(graph.HasEdge(3, 2));
  EXPECT_TRUE(graph.IsNaturalSuccessor(3, 4));
  EXPECT_FALSE(graph.IsNaturalSuccessor(2, 3));
  ASSERT_EQ(graph.successors(1).size(), 2u);
  EXPECT_EQ(graph.successors(1)[0], 1);
  EXPECT_EQ(graph.successors(1)[1], 2);
  ASSERT_EQ(graph.predecessors(0).size(), 1u);
  EXPECT_EQ(graph.predecessors(0)[0], 4);
  EXPECT_DOUBLE_EQ(graph.predecessor_costs(0)[0], 1.25);
  ASSERT_EQ(graph.predecessors(3).size(), 1u);
  EXPECT_DOUBLE_EQ(graph.predecessor_costs(3)[0], 0.25);
}

TEST(TransitionGraph, ValidSequencesFollowRealEdgesOnly) {
  const TransitionGraph graph(TwoClips(), {{2, 3, 0.5}});
  std::string why;
  EXPECT_TRUE(graph.IsValidSequence(std::vector<int>{0, 1, 2, 3, 4}, &why)) << why;
  EXPECT_FALSE(graph.IsValidSequence(std::vector<int>{0, 1, 3}, &why));
  EXPECT_NE(why.find("no edge 1 -> 3"), std::string::npos) << why;
  EXPECT_FALSE(graph.IsValidSequence(std::vector<int>{}, &why));
  EXPECT_FALSE(graph.IsValidSequence(std::vector<int>{0, 9}, &why));
}

TEST(TransitionGraph, TagsAndBadInput) {
  const TransitionGraph graph(TwoClips(), {});
  const std::vector<bool> standing = graph.FramesWithTag("standing");
  EXPECT_EQ(standing, (std::vector<bool>{false, false, false, true, false}));
  EXPECT_THROW(TransitionGraph(TwoClips(), {{0, 5, 1.0}}), InputError);
  EXPECT_THROW(TransitionGraph(TwoClips(), {{0, 1, -1.0}}), InputError);
  try {
    const TransitionGraph graph_with_nan(TwoClips(), {{0, 1, 1.0}, {0, 1, std::nan("")}});
    FAIL() << "a NaN cost was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("transitions[1]"), std::string::npos) << e.what();
  }
}

// Floor sprites (issue 38): a sprite filmed walking east that goes on as one filmed walking
// north is turned a quarter back, so it goes on east facing east; the turn holds until the next
// transition, and the track, the sequence file and the player carry it.
TEST(TransitionGraph, AFloorSpriteIsTurnedAtATransitionAndGoesOnTheWayItWent) {
  std::vector<FrameInfo> frames(6);
  for (int i = 0; i < 3; ++i) {  // clip 1: east, facing east; clip 2: north, facing north
    frames[i].clip = 1;
    frames[i].velocity_m = {0.01, 0};
    frames[i].heading_rad = 0.0;
    frames[i + 3].clip = 2;
    frames[i + 3].velocity_m = {0, 0.01};
    frames[i + 3].heading_rad = M_PI / 2;
  }
  const TransitionGraph graph(frames, {{1, 3, 0.5}, {5, 0, 0.5}});
  ASSERT_TRUE(graph.has_floor_frames());
  EXPECT_DOUBLE_EQ(graph.Turn(0, 1), 0.0) << "a natural successor does not turn";
  // After frame 1 the sprite faced east (frame 2's heading); frame 3 faced north.
  EXPECT_NEAR(graph.Turn(1, 3), -M_PI / 2, 1e-12);
  // At a clip's end its own heading: frame 5 faced north, frame 0 east.
  EXPECT_NEAR(graph.Turn(5, 0), M_PI / 2, 1e-12);

  const Track track = MakeTrack(graph, {0, 1, 3, 4, 5}, Anchor::kStart, {0, 0});
  ASSERT_EQ(track.turns_rad.size(), 5u);
  EXPECT_NEAR(track.turns_rad[1], 0.0, 1e-12);
  EXPECT_NEAR(track.turns_rad[2], -M_PI / 2, 1e-12);
  EXPECT_NEAR(track.turns_rad[4], -M_PI / 2, 1e-12);
  EXPECT_NEAR((track.positions_m[4] - Eigen::Vector2d(0.04, 0)).norm(), 0, 1e-12)
      << "it walks on east: " << track.positions_m[4].transpose();
  // End-anchored, the end stays as filmed and the start turns instead.
  const Track back = MakeTrack(graph, {0, 1, 3, 4, 5}, Anchor::kEnd, {0, 0});
  EXPECT_NEAR(back.turns_rad[4], 0.0, 1e-12);
  EXPECT_NEAR(back.turns_rad[0], M_PI / 2, 1e-12);
  // Started facing south (a path that heads south), the same frames walk south and then on
  // south: every step turns a further quarter back.
  const Track south = MakeTrack(graph, {0, 1, 3, 4, 5}, Anchor::kStart, {0, 0}, -M_PI / 2);
  EXPECT_NEAR(south.turns_rad[0], -M_PI / 2, 1e-12);
  EXPECT_NEAR(south.turns_rad[4], -M_PI, 1e-12);
  EXPECT_NEAR((south.positions_m[4] - Eigen::Vector2d(0, -0.04)).norm(), 0, 1e-12)
      << "it walks south: " << south.positions_m[4].transpose();
  // End-anchored facing west: the end turns a half turn from north, the start from east.
  const Track west = MakeTrack(graph, {0, 1, 3, 4, 5}, Anchor::kEnd, {0, 0}, M_PI);
  EXPECT_NEAR(std::abs(west.turns_rad[4]), M_PI / 2, 1e-12);
  EXPECT_NEAR(std::abs(std::remainder(west.turns_rad[0] - M_PI, 2 * M_PI)), 0, 1e-12);
  // Upright frames never turn.
  EXPECT_FALSE(TransitionGraph(TwoClips(), {}).has_floor_frames());
  EXPECT_TRUE(
      MakeTrack(TransitionGraph(TwoClips(), {}), {0, 1}, Anchor::kStart, {0, 0}).turns_rad.empty());
}

TEST(TransitionGraph, ASequenceFileKeepsTheTurns) {
  ScratchDir dir;
  SequenceFile file;
  file.camera_path = "virtual.cameramodel";
  file.bank_paths = {"bank.ssbank"};
  SpriteSequence s;
  s.name = "hamster";
  s.frames = {{0, 11}, {0, 12}};
  s.positions_m = {{0, 0}, {0.01, 0}};
  s.turns_rad = {0.0, -1.5};
  file.sprites = {s};
  file.num_steps = 2;
  WriteSequenceFile(dir / "seq.json", file);
  const SequenceFile read = ReadSequenceFile(dir / "seq.json");
  ASSERT_EQ(read.sprites.size(), 1u);
  EXPECT_EQ(read.sprites[0].turns_rad, s.turns_rad);
  // Without turns (upright sprites) the steps stay four numbers and read back without.
  file.sprites[0].turns_rad.clear();
  WriteSequenceFile(dir / "upright.json", file);
  EXPECT_TRUE(ReadSequenceFile(dir / "upright.json").sprites[0].turns_rad.empty());
  EXPECT_DOUBLE_EQ(read.sprites[0].TurnAt(9), 0.0);
}

}  // namespace
}  // namespace ss
