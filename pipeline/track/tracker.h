#pragma once
// Links sprite candidates across the frames of one camera into subjects, by
// their ground contact points: each new candidate joins the nearest live
// subject within reach (speed limit x elapsed time), greedily by distance;
// unmatched candidates start new subjects; subjects unseen for a while end.
#include <cstdint>
#include <vector>

#include <Eigen/Core>

namespace ss {

struct TrackerOptions {
  double max_speed_m_per_s = 1.0;  // a subject cannot move faster than this
  double reach_slack_m = 0.02;     // plus this, for keying jitter of the contact point
  double max_area_ratio = 2.5;     // a blob that grows or shrinks more is not the same sprite
  int64_t forget_after_ns = 500'000'000;
};

struct TrackInput {
  Eigen::Vector2d point_in_ground;  // contact point on the floor
  double area = 0;                  // matte area, pixels
};

class Tracker {
 public:
  explicit Tracker(TrackerOptions options = {}) : options_(options) {}
  // Subject id for each input of the frame at `timestamp_ns` (same order).
  std::vector<int> Update(int64_t timestamp_ns, const std::vector<TrackInput>& inputs);
  int live_subjects() const { return static_cast<int>(subjects_.size()); }

 private:
  struct Subject {
    int id;
    Eigen::Vector2d point;
    double area;
    int64_t last_seen_ns;
  };
  TrackerOptions options_;
  std::vector<Subject> subjects_;
  int next_id_ = 0;
};

// Cuts each subject's frames into clips: runs of consecutive usable frames.
// A clip ends when its subject is unusable, unseen in a frame, or gone.
class ClipCutter {
 public:
  struct Event {
    int subject;
    int64_t clip;  // the clip the frame joins, -1 when the frame is not usable
    bool closes;   // a clip closed (the subject's previous clip, `closed_clip`)
    int64_t closed_clip = -1;
  };
  // Call once per frame with every subject seen and whether its sprite is usable.
  // Returns one event per input, plus closings of clips whose subject was not seen.
  std::vector<Event> Update(const std::vector<int>& subjects, const std::vector<bool>& usable);
  // Closes every open clip (end of stream); returns their ids.
  std::vector<int64_t> CloseAll();

 private:
  struct Open {
    int subject;
    int64_t clip;
  };
  std::vector<Open> open_;
  int64_t next_clip_ = 0;
};

}  // namespace ss
