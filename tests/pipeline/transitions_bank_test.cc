// Transitions of a real sprite bank: the bank build equals the in-memory build, the
// incremental worker equals a from-scratch build, labels from truth, the command line
// and its error messages.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <set>

#include <nlohmann/json.hpp>

#include "core/bank.h"
#include "core/error.h"
#include "pipeline/transitions/bank_training.h"
#include "pipeline/transitions/bank_transitions.h"
#include "pipeline/transitions/builder.h"
#include "pipeline/transitions/synthetic.h"
#include "pipeline/transitions/worker.h"
#include "tests/pipeline/transitions_test_util.h"
#include "tests/support/test_support.h"

namespace ss {
namespace {

// Generous weights for the synthetic set so that many pairs and transitions exist.
TransitionWeights Generous() {
  return testing::UnitWeights({0.03, 30, 0.0006, 0.04, 0.12, 12}, 4.0, 3.0);
}

constexpr int64_t kFrameNs = 33'333'333;

// A synthetic set whose area survives the bank's round trip bit for bit.
std::vector<SyntheticSprite> Sprites(int frames, uint64_t seed) {
  SyntheticSpriteOptions o;
  o.frames = frames;
  o.min_clip_frames = 10;
  o.max_clip_frames = 60;
  o.seed = seed;
  auto sprites = MakeSyntheticSprites(o);
  for (auto& s : sprites) {
    const double area_px = s.cheap.area_m2 * o.px_per_m * o.px_per_m;
    s.cheap.area_m2 = area_px / (o.px_per_m * o.px_per_m);
  }
  return sprites;
}

// One synthetic clip (originals and their mirrors) as one bank clip.
struct ClipOfSprites {
  int64_t clip = 0;
  std::vector<const SyntheticSprite*> originals, mirrors;  // by frame
};
std::vector<ClipOfSprites> Clips(const std::vector<SyntheticSprite>& sprites) {
  const size_t half = sprites.size() / 2;
  std::map<int64_t, ClipOfSprites> by_clip;
  for (size_t k = 0; k < half; ++k) {
    auto& c = by_clip[sprites[k].clip];
    c.clip = sprites[k].clip;
    c.originals.push_back(&sprites[k]);
    c.mirrors.push_back(&sprites[half + k]);
  }
  std::vector<ClipOfSprites> out;
  for (auto& [id, c] : by_clip) out.push_back(c);
  return out;
}

SpriteRecord Record(const SyntheticSprite& s, int64_t frame, bool mirrored) {
  const double px_per_m = SyntheticSpriteOptions{}.px_per_m;
  SpriteRecord r;
  r.frame = frame;
  r.timestamp_ns = frame * kFrameNs;
  r.mirrored = mirrored;
  r.ground_x_m = 0.001 * frame;
  r.ground_y_m = 0.5;
  r.velocity_x_m_s = s.cheap.velocity_x_mps;
  r.velocity_y_m_s = s.cheap.velocity_y_mps;
  r.mean_r = s.cheap.colour[0];
  r.mean_g = s.cheap.colour[1];
  r.mean_b = s.cheap.colour[2];
  r.area_px = s.cheap.area_m2 * px_per_m * px_per_m;
  r.eccentricity = s.cheap.eccentricity;
  r.billboard_width_px = s.billboard.width;
  r.billboard_height_px = s.billboard.height;
  r.px_per_m = px_per_m;
  r.anchor_x_px = s.billboard.anchor_x_px;
  r.anchor_y_px = s.billboard.anchor_y_px;
  r.bbox_in_image = cv::Rect(0, 0, s.billboard.width, s.billboard.height);
  if (!mirrored) {
    r.pixels.bgra = cv::Mat(s.billboard.height, s.billboard.width, CV_8UC4,
                            const_cast<uint8_t*>(s.billboard.rgba.data()))
                        .clone();
  }
  return r;
}

// Writes clips into a bank, `batch` frames per transaction; `stored` is called with the
// ids of every batch (as the pipeline would hand them to the worker).
class BankFiller {
 public:
  explicit BankFiller(const std::string& path) : writer_(path) {
    const int64_t session = writer_.AddSession({0, "synthetic@test", "synthetic", "", "test"});
    camera_ = writer_.AddCamera(session, {0, 0, "cam0", "", 640, 480});
  }
  // Stores one clip; fills bank_id for its sprites.
  void Add(const ClipOfSprites& c, int batch,
           const std::function<void(const std::vector<int64_t>&)>& stored = {}) {
    ClipRecord clip;
    clip.camera_id = camera_;
    clip.track_id = c.clip;
    clip.first_frame = next_frame_;
    for (size_t begin = 0; begin < c.originals.size(); begin += batch) {
      const size_t end = std::min(c.originals.size(), begin + batch);
      std::vector<SpriteRecord> records;
      std::vector<int64_t> synthetic_ids;
      for (size_t k = begin; k < end; ++k) {
        records.push_back(Record(*c.originals[k], next_frame_ + static_cast<int64_t>(k), false));
        synthetic_ids.push_back(c.originals[k]->id);
        records.push_back(Record(*c.mirrors[k], next_frame_ + static_cast<int64_t>(k), true));
        synthetic_ids.push_back(c.mirrors[k]->id);
        if (merged.count(c.originals[k]->id)) {  // tagged in the sprite's own batch
          records[records.size() - 2].tags = {kMergedTag};
          records.back().tags = {kMergedTag};
        }
      }
      clip.complete = end == c.originals.size();
      clip.last_frame = next_frame_ + static_cast<int64_t>(end) - 1;
      const AppendResult r = writer_.AppendClipBatch(clip, records);
      for (size_t k = 0; k < r.sprite_ids.size(); ++k) bank_id[synthetic_ids[k]] = r.sprite_ids[k];
      if (stored) stored(r.sprite_ids);
    }
    next_frame_ += static_cast<int64_t>(c.originals.size()) + 10;  // a gap between clips
  }
  std::map<int64_t, int64_t> bank_id;  // synthetic id -> bank id
  std::set<int64_t> merged;            // synthetic ids of originals stored tagged merged

 private:
  BankWriter writer_;
  int64_t camera_ = 0;
  int64_t next_frame_ = 100;
};

std::vector<TransitionRecord> Sorted(std::vector<TransitionRecord> t) {
  std::sort(t.begin(), t.end(), [](const auto& a, const auto& b) {
    return std::tie(a.from_sprite, a.to_sprite) < std::tie(b.from_sprite, b.to_sprite);
  });
  return t;
}

TEST(TransitionBank, BankBuildEqualsInMemoryBuild) {
  testing::ScratchDir dir;
  const auto sprites = Sprites(300, 3);
  BankFiller filler(dir / "bank.db");
  for (const auto& c : Clips(sprites)) filler.Add(c, 25);

  BankUpdateOptions options;
  options.weights = Generous();
  const BankUpdateSummary s = UpdateBankTransitions(dir / "bank.db", options);
  EXPECT_EQ(s.sprites, 600);

  TransitionBuilder memory(Generous(), SyntheticSpriteOptions{}.px_per_m);
  memory.BuildFromScratch(AsSpriteInputs(sprites));
  std::vector<TransitionRecord> want;
  for (const Transition& t : memory.Transitions()) {
    want.push_back({filler.bank_id.at(t.from), filler.bank_id.at(t.to), t.distance, t.cost});
  }
  ASSERT_GT(want.size(), 100u);
  const auto got = Bank(dir / "bank.db").LoadTransitions();
  ASSERT_EQ(got.size(), want.size());
  const auto sorted = Sorted(want);
  for (size_t k = 0; k < got.size(); ++k) {
    EXPECT_EQ(got[k].from_sprite, sorted[k].from_sprite);
    EXPECT_EQ(got[k].to_sprite, sorted[k].to_sprite);
    EXPECT_NEAR(got[k].d, sorted[k].d, 1e-9);  // area_px / px_per_m^2 may round in the last bit
    EXPECT_NEAR(got[k].cost, sorted[k].cost, 1e-9);
  }
  EXPECT_EQ(s.store.added, static_cast<int64_t>(want.size()));

  // Running it again finds nothing to write; other weights replace the table.
  const BankUpdateSummary again = UpdateBankTransitions(dir / "bank.db", options);
  EXPECT_EQ(again.store.added + again.store.changed + again.store.removed, 0);
  EXPECT_EQ(again.store.unchanged, static_cast<int64_t>(want.size()));
  options.weights = testing::UnitWeights({0.03, 30, 0.0006, 0.04, 0.12, 12}, 2.0, 1.5);
  const BankUpdateSummary other = UpdateBankTransitions(dir / "bank.db", options);
  EXPECT_TRUE(other.store.replaced_all);
  EXPECT_LT(other.transitions, static_cast<int64_t>(want.size()));
  EXPECT_EQ(Bank(dir / "bank.db").LoadTransitions().size(), static_cast<size_t>(other.transitions));
}

TEST(TransitionBank, WorkerEqualsFromScratch) {
  testing::ScratchDir dir;
  const auto sprites = Sprites(400, 4);
  const auto clips = Clips(sprites);
  ASSERT_GT(clips.size(), 6u);
  BankFiller filler(dir / "bank.db");
  // A third of the clips are in the bank before the worker starts.
  const size_t before = clips.size() / 3;
  for (size_t k = 0; k < before; ++k) filler.Add(clips[k], 50);
  {
    TransitionWorker worker(dir / "bank.db", Generous());
    for (size_t k = before; k < clips.size(); ++k) {
      filler.Add(clips[k], 7, [&](const std::vector<int64_t>& ids) { worker.Submit(ids); });
    }
    worker.WaitIdle();
    const TransitionWorkerStats st = worker.stats();
    EXPECT_TRUE(st.ready);
    EXPECT_EQ(st.failed_rounds, 0) << st.last_error;
    EXPECT_EQ(st.sprites, 800);
    EXPECT_EQ(st.queued, 0);
  }
  const auto incremental = Bank(dir / "bank.db").LoadTransitions();
  ASSERT_GT(incremental.size(), 100u);
  // A from-scratch build of the whole bank finds exactly the same table.
  BankUpdateOptions options;
  options.weights = Generous();
  const BankUpdateSummary s = UpdateBankTransitions(dir / "bank.db", options);
  EXPECT_EQ(s.transitions, static_cast<int64_t>(incremental.size()));
  EXPECT_EQ(s.store.added, 0);
  EXPECT_EQ(s.store.changed, 0);
  EXPECT_EQ(s.store.removed, 0);
  EXPECT_FALSE(s.store.replaced_all);
}

// Sprites tagged merged (two subjects in one blob) take part in no transition, on the worker
// path (start-up and rounds) and in a single-process build alike, unless included.
TEST(TransitionBank, MergedSpritesTakePartOnlyWhenIncluded) {
  testing::ScratchDir dir;
  const std::string bank = dir / "bank.db";
  const auto sprites = Sprites(400, 5);
  const auto clips = Clips(sprites);
  ASSERT_GT(clips.size(), 6u);
  BankFiller filler(bank);
  // In every clip, 3 frames a third of the way in (the clip's segment is cut there).
  for (const auto& c : clips) {
    const size_t at = c.originals.size() / 3;
    for (size_t k = at; k < at + 3 && k < c.originals.size(); ++k)
      filler.merged.insert(c.originals[k]->id);
  }
  const auto touches_merged = [&](const std::vector<TransitionRecord>& table) {
    const std::vector<int64_t> tagged = Bank(bank).SpritesTagged(kMergedTag);
    const std::set<int64_t> m(tagged.begin(), tagged.end());
    int64_t n = 0;
    for (const TransitionRecord& t : table) n += m.count(t.from_sprite) || m.count(t.to_sprite);
    return n;
  };
  const size_t before = clips.size() / 3;
  for (size_t k = 0; k < before; ++k) filler.Add(clips[k], 50);
  {
    TransitionWorker worker(bank, Generous());
    for (size_t k = before; k < clips.size(); ++k)
      filler.Add(clips[k], 7, [&](const std::vector<int64_t>& ids) { worker.Submit(ids); });
    worker.WaitIdle();
    EXPECT_EQ(worker.stats().failed_rounds, 0) << worker.stats().last_error;
    EXPECT_EQ(worker.stats().sprites, 800 - 2 * static_cast<int64_t>(filler.merged.size()));
  }
  EXPECT_EQ(Bank(bank).SpritesTagged(kMergedTag).size(), 2 * filler.merged.size());
  const auto incremental = Bank(bank).LoadTransitions();
  ASSERT_GT(incremental.size(), 100u);
  EXPECT_EQ(touches_merged(incremental), 0);
  EXPECT_EQ(Bank(bank).GetMeta(SpriteChoice::kMetaKey).value_or(""), "false");

  // The single-process build leaves them out too, and finds the worker's table.
  BankUpdateOptions options;
  options.weights = Generous();
  const BankUpdateSummary s = UpdateBankTransitions(bank, options);
  EXPECT_EQ(s.left_out, 2 * static_cast<int64_t>(filler.merged.size()));
  EXPECT_EQ(s.transitions, static_cast<int64_t>(incremental.size()));
  EXPECT_EQ(s.store.added + s.store.changed + s.store.removed, 0);

  // Included, they have transitions; left out again, those go.
  options.sprites.include_merged = true;
  const BankUpdateSummary with = UpdateBankTransitions(bank, options);
  EXPECT_EQ(with.left_out, 0);
  EXPECT_GT(touches_merged(Bank(bank).LoadTransitions()), 0);
  EXPECT_EQ(Bank(bank).GetMeta(SpriteChoice::kMetaKey).value_or(""), "true");
  options.sprites.include_merged = false;
  const BankUpdateSummary without = UpdateBankTransitions(bank, options);
  EXPECT_GT(without.store.removed, 0);
  EXPECT_EQ(touches_merged(Bank(bank).LoadTransitions()), 0);
  // A worker starting on a table made with them drops their transitions at start.
  options.sprites.include_merged = true;
  UpdateBankTransitions(bank, options);
  {
    TransitionWorker worker(bank, Generous());
    worker.WaitIdle();
  }
  EXPECT_EQ(touches_merged(Bank(bank).LoadTransitions()), 0);
}

TEST(TransitionBank, EmptyBankOneClipAndMissingBank) {
  testing::ScratchDir dir;
  { BankWriter make(dir / "empty.db"); }
  BankUpdateOptions options;
  options.weights = Generous();
  try {
    UpdateBankTransitions(dir / "empty.db", options);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("no sprites"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("empty.db"), std::string::npos) << e.what();
  }
  EXPECT_THROW(UpdateBankTransitions(dir / "missing.db", options), InputError);
  EXPECT_FALSE(std::filesystem::exists(dir / "missing.db")) << "a missing bank must not be created";

  const auto sprites = Sprites(60, 5);
  BankFiller filler(dir / "one.db");
  filler.Add(Clips(sprites)[0], 100);
  const BankUpdateSummary s = UpdateBankTransitions(dir / "one.db", options);
  EXPECT_EQ(s.clips, 1);
  ASSERT_FALSE(s.notes.empty());
  EXPECT_NE(s.notes[0].find("one clip"), std::string::npos);

  // The worker on an empty bank starts empty and learns the bank's scale from its first sprites.
  TransitionWorker worker(dir / "empty.db", Generous());
  worker.WaitIdle();
  EXPECT_TRUE(worker.stats().ready);
  EXPECT_EQ(worker.stats().failed_rounds, 0) << worker.stats().last_error;
  TransitionWorker missing(dir / "missing2.db", Generous());
  missing.WaitIdle();
  EXPECT_EQ(missing.stats().failed_rounds, 1);
  EXPECT_NE(missing.stats().last_error.find("missing2.db"), std::string::npos)
      << missing.stats().last_error;
}

// A session folder whose truth/subjects.csv describes the synthetic sprites as stored by
// BankFiller.
void WriteTruth(const std::string& session_dir, const std::vector<SyntheticSprite>& sprites) {
  std::filesystem::create_directories(std::filesystem::path(session_dir) / "truth");
  std::ofstream out(std::filesystem::path(session_dir) / "truth" / "subjects.csv");
  out.precision(17);
  out << "frame,timestamp_ns,subject,kind,x,y,heading_rad,speed_mps,gait_phase,pose,touches_wall,"
         "leaves_floor,"
         "height_m\n";
  int64_t frame = 100;
  for (const auto& c : Clips(sprites)) {
    for (const SyntheticSprite* s : c.originals) {
      out << frame << ',' << frame * kFrameNs << ",0,animal," << 0.001 * frame << ",0.5,"
          << s->truth.heading_rad << ',' << s->speed_mps << ',' << s->truth.gait_phase << ','
          << s->truth.pose << ",0,0,0.1\n";
      // A second subject far away must not be matched.
      out << frame << ',' << frame * kFrameNs << ",1,animal,5,5,0,0,0.5,stand,0,0,0.1\n";
      ++frame;
    }
    frame += 10;
  }
}

TEST(TransitionBank, LabelsFromSessionTruth) {
  testing::ScratchDir dir;
  const auto sprites = Sprites(300, 6);
  BankFiller filler(dir / "bank.db");
  for (const auto& c : Clips(sprites)) filler.Add(c, 40);
  WriteTruth(dir / "session", sprites);
  const TruthLabelSummary s =
      LabelBankFromTruth(dir / "session", dir / "bank.db", 200, TruthLabelOptions{}, 1);
  EXPECT_EQ(s.sprites_matched, 300);
  EXPECT_EQ(s.mirrored_skipped, 300);
  ASSERT_EQ(s.labels.size(), 200u);
  std::map<int64_t, const SyntheticSprite*> by_bank_id;
  for (const auto& sp : sprites) by_bank_id[filler.bank_id.at(sp.id)] = &sp;
  TruthLabelOptions phase_only;  // the session truth has no key points: heading and phase decide
  for (const Label& l : s.labels) {
    SpriteTruth a = by_bank_id.at(l.sprite_i)->truth, b = by_bank_id.at(l.sprite_j)->truth;
    a.keypoints_m.clear();
    b.keypoints_m.clear();
    EXPECT_EQ(l.accept, TruthAccepts(a, b, phase_only));
    EXPECT_FALSE(by_bank_id.at(l.sprite_i)->id > 300) << "mirrors are left out";
  }
  EXPECT_THROW(LabelBankFromTruth(dir / "nosession", dir / "bank.db", 200, TruthLabelOptions{}, 1),
               InputError);
}

TEST(TransitionBank, CommandLine) {
  testing::ScratchDir dir;
  const auto sprites = Sprites(300, 7);
  BankFiller filler(dir / "bank.db");
  for (const auto& c : Clips(sprites)) filler.Add(c, 40);
  WriteTruth(dir / "session", sprites);
  const std::string bank = dir / "bank.db";

  // label -> train -> build with the trained weights.
  auto r =
      testing::RunSpritestation("transitions label --from-truth " + (dir / "session") + " --bank " +
                                bank + " --out " + (dir / "labels.csv") + " --count 300");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  r = testing::RunSpritestation("transitions train " + (dir / "labels.csv") + " --bank " + bank +
                                " --out " + (dir / "w.json") + " --threads 1");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("stage 2 (all 6 features):   precision"), std::string::npos) << r.output;
  // The labels carry the truth's positive rate, so stage 2 is set for it and stage 1 refitted.
  double rate = 0;
  ReadLabelsCsv(dir / "labels.csv", &rate);
  EXPECT_GT(rate, 0.0);
  EXPECT_LT(rate, 0.5);
  EXPECT_NE(r.output.find("stage 2 then set for the positive rate"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("stage 1 refitted as its filter"), std::string::npos) << r.output;
  EXPECT_NO_THROW(LoadWeights(dir / "w.json"));
  r = testing::RunSpritestation("transitions " + bank + " --weights " + (dir / "w.json") +
                                " --json");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const auto j = nlohmann::json::parse(r.output.substr(r.output.find('{')));
  EXPECT_EQ(j["sprites"], 600);
  EXPECT_EQ(j["transitions"].get<int64_t>(),
            static_cast<int64_t>(Bank(bank).LoadTransitions().size()));
  r = testing::RunSpritestation("transitions " + bank);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("finding transitions"), std::string::npos)
      << "progress lines: " << r.output;

  // Clear messages: wrong weights file, empty bank, no bank, labels naming unknown sprites.
  std::ofstream(dir / "bad.json")
      << R"({"format": "spritestation-transition-weights", "version": 7})";
  r = testing::RunSpritestation("transitions " + bank + " --weights " + (dir / "bad.json"));
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("bad.json"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("version"), std::string::npos) << r.output;
  { BankWriter make(dir / "empty.db"); }
  r = testing::RunSpritestation("transitions " + (dir / "empty.db"));
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("no sprites"), std::string::npos) << r.output;
  r = testing::RunSpritestation("transitions " + (dir / "none.db"));
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("no such sprite bank"), std::string::npos) << r.output;
  std::ofstream(dir / "unknown.csv") << "sprite_i,sprite_j,accept\n1,999999,1\n";
  r = testing::RunSpritestation("transitions train " + (dir / "unknown.csv") + " --bank " + bank +
                                " --out " + (dir / "w2.json"));
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("999999"), std::string::npos) << r.output;
}

}  // namespace
}  // namespace ss
