#include "animate/transition_graph.h"

#include <gtest/gtest.h>

#include "core/error.h"

namespace ss {
namespace {

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

}  // namespace
}  // namespace ss
