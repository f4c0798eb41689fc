#pragma once
// Links sprite candidates across the frames of one camera into subjects, by
// their ground contact points: each new candidate joins the nearest live
// subject within reach (speed limit x elapsed time), greedily by distance;
// unmatched candidates start new subjects; subjects unseen for a while end.
#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

namespace ss {

struct TrackerOptions {
  double max_speed_m_per_s = 1.0;  // a subject cannot move faster than this
  double reach_slack_m = 0.02;     // plus this, for keying jitter of the contact point
  double max_area_ratio = 2.5;     // a blob that grows or shrinks more is not the same sprite
  int64_t forget_after_ns = 500'000'000;  // a subject unseen this long has ended
  // False with "FIELD: reason" lines in `why` (core/option_checks.h) for values out of range.
  bool IsValid(std::string* why) const;
  bool operator==(const TrackerOptions&) const = default;
};

struct TrackInput {
  Eigen::Vector2d point_in_ground;  // contact point on the floor
  double area = 0;                  // matte area, pixels
};

class Tracker {
 public:
  // InputError naming the field when `options` are out of range (TrackerOptions::IsValid).
  explicit Tracker(TrackerOptions options = {});
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

// Which blobs hold two or more subjects (issue 19: "two subjects merged into one blob are
// marked"), from the tracker's evidence frame to frame, not from the blob's looks. Each blob
// carries a count of the subjects in it, handed on from the tracks of the frame before:
//   - a track seen in the frame before hands its count to the blob the tracker gave it, unless
//     it split (below);
//   - a track of the frame before that got no blob this frame, whose box lies mostly
//     (>= absorb_share of its area) inside one blob's box, was swallowed by that blob: it adds its
//     count to that blob (two tracks meeting in one blob: a merge) when it had been seen for at
//     least min_track_frames frames in a row (a piece of a subject keyed apart for a frame or
//     two and joined again is no second subject); a blob made of one lost track only is that
//     track going on under a new id, and takes its count whatever its age;
//   - a track of the frame before whose box holds (>= split_share of their area) two or more
//     blobs of this frame, its own and ones whose track was not seen in the frame before (new or
//     found again; such a blob is a piece of the smallest box holding it only), split: each of them
//     counts one subject, but a piece keeping most of a merged blob's area (>= keep_area_share)
//     keeps its count (the other piece was a part keyed apart), less the counts of pieces that are
//     tracks it swallowed, come out under their own ids again; the pieces of a merged blob count
//     as seen long enough, so that they merge again at once;
//   - a blob without a track of the frame before counts one subject.
// A blob counting two or more is `merged`. A merged blob whose area falls under
// drop_area_share of its area when it merged counts one again (the partner left unseen).
class MergeDetector {
 public:
  struct Options {
    double absorb_share = 0.5;      // of a lost track's box inside the blob's box
    double split_share = 0.5;       // of a new blob's box inside its parent's box
    double drop_area_share = 0.5;   // of the area at the merge
    int min_track_frames = 3;       // frames a swallowed track must have been seen in a row
    double keep_area_share = 0.75;  // of a merged blob's area, for a piece to keep its count
  };
  struct Blob {
    int track = -1;   // the tracker's subject id
    cv::Rect box;     // in the image
    double area = 0;  // matte area, pixels
  };
  MergeDetector() = default;
  explicit MergeDetector(Options options) : options_(options) {}
  // One frame's blobs (every tracked candidate); true for each that holds two or more subjects.
  std::vector<bool> Update(const std::vector<Blob>& blobs);
  // After a frame was lost: nothing carries over.
  void Reset() { previous_.clear(); }

 private:
  struct Seen {
    int track;
    cv::Rect box;
    int subjects;        // how many the blob held
    double merged_area;  // its area when it became merged (subjects >= 2)
    int frames;          // frames in a row the track was seen
    double area;
    std::vector<int> members;  // tracks swallowed into it and counted (subjects >= 2)
  };
  Options options_;
  std::vector<Seen> previous_;
  int64_t updates_ = 0;  // frames seen, for the debug log
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
