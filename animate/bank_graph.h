#pragma once
// The transition graph of one or more sprite banks (core/bank.h). Every sprite of a
// complete clip is a frame; the runs of consecutive source frames of a clip (originals and
// mirrored copies apart) give the natural successors, the bank's transitions the rest.
// A frame's ground displacement per step is its stored velocity times the bank's source
// frame interval (the median timestamp step within clips), so positions integrate what
// the subject really moved between source frames, whatever the playback rate.
// Frames of several banks are pooled; no transition joins two banks.
#include <atomic>
#include <cstdint>
#include <string>
#include <vector>

#include "animate/transition_graph.h"

namespace ss {

// Which bank sprite a graph frame is.
struct BankFrameRef {
  int bank = 0;           // index into BankGraph::bank_paths
  int64_t sprite_id = 0;  // the sprite's id in that bank
};

struct BankGraph {
  TransitionGraph graph;
  std::vector<BankFrameRef> frames;  // one per graph frame
  std::vector<std::string> bank_paths;
  std::vector<double> frame_interval_s;  // per bank: the source frame interval used
  // Graph frame of (bank, sprite id); -1 if not in the graph.
  int FrameOf(int bank, int64_t sprite_id) const;
};

// Loads the banks. `tags` are the tag names to attach to frames (those the spec asks for;
// "mirrored" is always attached to mirrored copies). InputError naming a bank that cannot be
// opened or holds no sprites. `cancel`, set by another thread, stops the load between its reads
// (WorkError "BANK: cancelled").
BankGraph LoadBankGraph(const std::vector<std::string>& bank_paths,
                        const std::vector<std::string>& tags,
                        const std::atomic<bool>* cancel = nullptr);

}  // namespace ss
