// The sprite bank on PostgreSQL (issue 21): the same semantics as on SQLite, many writers at
// once, a server that goes away and comes back, and `bank copy` both ways. Each test starts a
// private server (tests/support/postgres_server.h).
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <map>
#include <set>
#include <thread>
#include <vector>

#include "core/bank.h"
#include "core/bank_copy.h"
#include "core/bank_verify.h"
#include "core/error.h"
#include "core/error_kinds.h"
#include "tests/support/bank_fixtures.h"
#include "tests/support/postgres_server.h"
#include "tests/support/test_support.h"

namespace ss {
namespace {

using namespace ss::testing;  // NOLINT: the bank fixtures, ScratchDir, PostgresServer

// Everything a reader can ask of a bank, as one comparable text. Sprite ids are given as their
// rank: PostgreSQL's sequences leave gaps where SQLite reuses the next number (a re-sent sprite
// draws an id it does not keep), and ids are only ever compared, never counted.
std::string Describe(const Bank& bank) {
  std::map<int64_t, int64_t> rank = {{0, 0}};
  for (const auto& f : bank.LoadFeatures()) rank[f.id] = 0;
  int64_t next = 0;
  for (auto& [id, r] : rank) r = next++;
  auto Id = [&](int64_t id) { return static_cast<long long>(rank.at(id)); };
  std::string out;
  for (const auto& s : bank.ListSessions())
    out += "session " + std::to_string(s.id) + " " + s.uid + " " + s.name + "\n";
  for (const auto& c : bank.ListCameras()) {
    out += "camera " + std::to_string(c.id) + " " + c.name + " " + std::to_string(c.width) + "x" +
           std::to_string(c.height) + " model " + std::to_string(c.cameramodel.size()) + "\n";
  }
  for (const auto& c : bank.ListAllClips()) {
    out += "clip " + std::to_string(c.id) + " " + std::to_string(c.first_frame) + ".." +
           std::to_string(c.last_frame) + " complete " + std::to_string(c.complete_seq) + "\n";
  }
  for (const auto& f : bank.LoadFeatures()) {
    const SpriteRecord s = bank.LoadSprite(f.id);
    char line[512];
    std::snprintf(
        line, sizeof(line),
        "sprite %lld clip %lld frame %lld m%d of %lld %.17g %.17g %.17g %.17g %.17g %.17g\n",
        Id(s.id), static_cast<long long>(s.clip_id), static_cast<long long>(s.frame),
        s.mirrored ? 1 : 0, Id(s.mirror_of), s.ground_x_m, s.ground_y_m, s.velocity_x_m_s, s.mean_g,
        s.area_px, s.anchor_y_px);
    out += line;
    for (const auto& t : s.tags) out += " tag " + t + "\n";
    const SpritePixels p = bank.LoadPixels(f.id);
    out += " pixels " +
           std::to_string(cv::sum(p.bgra)[0] + 7 * cv::sum(p.bgra)[3] + 3 * cv::sum(p.shadow)[0]) +
           "\n";
  }
  for (const auto& t : bank.LoadTransitions()) {
    char line[128];
    std::snprintf(line, sizeof(line), "transition %lld %lld %.17g %.17g\n", Id(t.from_sprite),
                  Id(t.to_sprite), t.d, t.cost);
    out += line;
  }
  for (const auto& l : bank.LoadTransitionLabels()) {
    out += "label " + std::to_string(Id(l.from_sprite)) + " " + std::to_string(Id(l.to_sprite)) +
           " " + l.label + "\n";
  }
  const BankCounts c = bank.Counts();
  out += "counts " + std::to_string(c.sprites) + " " + std::to_string(c.mirrors) + " " +
         std::to_string(c.transitions) + " " + std::to_string(c.tags) + " " +
         std::to_string(c.pixel_rows) + " v" + std::to_string(c.schema_version);
  return out;
}

// The same writes into any bank: two sessions, clips open and complete, re-sent batches,
// tags, transitions (with replacement), labels, meta.
void WriteScenario(const std::string& path) {
  BankWriter w(path);
  const Fixture fx = Register(w);
  const int64_t session2 =
      w.AddSession({0, "second@2026", "second", "2026-12-02T10:00:00Z", "test"});
  const int64_t camera2 = w.AddCamera(session2, {0, 0, "cam1", "# a model\n", 640, 480});
  std::vector<SpriteRecord> batch = MakeBatch(10, 14, 7);
  batch[1].tags = {"walk", "left"};
  w.AppendClipBatch(Clip(fx.camera, 7, 10, false), batch);
  w.AppendClipBatch(Clip(fx.camera, 7, 10, false), batch);  // re-sent: nothing new
  w.AppendClipBatch(Clip(fx.camera, 7, 10, true), MakeBatch(15, 16, 7));
  w.AppendClipBatch(Clip(camera2, 1, 0, true), MakeBatch(0, 3, 1, /*mirrors=*/false));
  w.AppendClipBatch(Clip(camera2, 2, 50, false), MakeBatch(50, 51, 2));  // stays open
  const auto f = w.LoadFeatures();
  ASSERT_GE(f.size(), 10u);
  w.UpsertTransitions({{f[0].id, f[2].id, 0.25, 1.5}, {f[2].id, f[0].id, 0.125, 1e-300}});
  w.UpsertTransitions({{f[0].id, f[2].id, 0.3333333333333333, 2.0 / 3.0}});
  // Four out of f[1], two of them at one cost: the cap keeps the two cheapest by (cost, to).
  ASSERT_LT(f[3].id, f[4].id);
  w.UpsertTransitions({{f[1].id, f[6].id, 0.5, 3.0},
                       {f[1].id, f[5].id, 0.5, 1.0},
                       {f[1].id, f[4].id, 0.5, 2.0},
                       {f[1].id, f[3].id, 0.5, 2.0}});
  std::vector<TransitionRecord> bars;
  EXPECT_EQ(w.PruneTransitions(std::vector<int64_t>{f[1].id, f[0].id}, 2, &bars), 2);
  ASSERT_EQ(bars.size(), 1u);  // f[0] holds one transition: under its cap, no bar
  EXPECT_EQ(bars[0].from_sprite, f[1].id);
  EXPECT_EQ(bars[0].to_sprite, f[3].id);
  EXPECT_EQ(bars[0].cost, 2.0);
  std::set<int64_t> kept;
  for (const TransitionRecord& t : w.LoadTransitionsFrom(f[1].id)) kept.insert(t.to_sprite);
  EXPECT_EQ(kept, (std::set<int64_t>{f[3].id, f[5].id}));
  w.Tag({f[3].id, f[4].id}, "jump");
  w.Untag({f[4].id}, "jump");
  w.SetTransitionLabel({f[0].id, f[5].id, "yes", "2026-12-02T10:00:01Z", "test"});
  w.SetTransitionLabel({f[5].id, f[6].id, "no", "2026-12-02T10:00:02Z", "test"});
  w.SetTransitionLabel({f[0].id, f[5].id, "skip", "2026-12-02T10:00:03Z", "test"});
  EXPECT_TRUE(w.RemoveTransitionLabel(f[5].id, f[6].id));
  EXPECT_FALSE(w.RemoveTransitionLabel(f[5].id, f[6].id));
  w.SetMeta("studio", "north");
  w.RenameSession(session2, "second take");
}

TEST(BankPostgres, HoldsWhatASqliteBankHolds) {
  PostgresServer server;
  ASSERT_TRUE(server.ok());
  ScratchDir dir;
  const std::string file = dir / "bank.db";
  const std::string pg = server.CreateDatabase("bank");
  WriteScenario(file);
  WriteScenario(pg);
  const Bank a(file), b(pg);
  EXPECT_TRUE(b.is_postgres());
  EXPECT_FALSE(a.is_postgres());
  const std::string want = Describe(a);
  EXPECT_EQ(Describe(b), want);
  EXPECT_NE(want.find("tag walk"), std::string::npos);
  EXPECT_EQ(b.GetMeta("studio"), "north");
  EXPECT_EQ(b.CountClipSprites(), a.CountClipSprites());
  EXPECT_EQ(b.CountClipTags(), a.CountClipTags());
  EXPECT_EQ(b.SpritesTagged("walk").size(), 1u);
  EXPECT_EQ(a.SpritesTagged("walk").size(), 1u);
  EXPECT_EQ(b.BillboardScales(), a.BillboardScales());
  EXPECT_EQ(b.ClipSpriteIds(1, 11, 12).size(), 4u);
  EXPECT_EQ(a.ClipSpriteIds(1, 11, 12).size(), 4u);
  EXPECT_EQ(b.ListClips(1).size(), a.ListClips(1).size());
  EXPECT_GT(b.Counts().file_bytes, 0);  // the tables' size on the server

  const BankVerifyReport report = VerifyBank(pg);
  EXPECT_TRUE(report.ok()) << report.problems.front();
  EXPECT_EQ(report.sprites_checked, a.Counts().sprites);
  EXPECT_EQ(DigestBank(pg).rows, DigestBank(file).rows);
  // Bad batches are refused whole, as on SQLite.
  BankWriter w(pg);
  std::vector<SpriteRecord> orphan = {MakeMirror(MakeSprite(99, 7))};
  EXPECT_THROW(w.AppendClipBatch(Clip(1, 7, 99, true), orphan), WorkError);
  EXPECT_THROW(w.AppendClipBatch(Clip(1, 7, 10, true), MakeBatch(17, 17, 7)),
               WorkError);  // complete clip grows
  EXPECT_THROW(w.Tag({123456}, "x"), InputError);
  EXPECT_EQ(Describe(Bank(pg)), want);
}

TEST(BankPostgres, ADatabaseThatIsNotABankIsNamedWithoutItsPassword) {
  PostgresServer server;
  ASSERT_TRUE(server.ok());
  const std::string address = server.CreateDatabase("other");
  {
    BankWriter w(address);  // a bank, then its meta says it is something else
    w.SetMeta("note", "x");
  }
  const std::string with_password =
      "postgresql://spritestation:hunter2@127.0.0.1:" + std::to_string(server.port()) + "/empty";
  try {
    Bank bank(with_password);
    FAIL() << "an address without a database opened";
  } catch (const WorkError& e) {
    const std::string what = e.what();
    EXPECT_EQ(what.find("hunter2"), std::string::npos) << what;
    EXPECT_NE(what.find("spritestation:***@127.0.0.1"), std::string::npos) << what;
  }
  const std::string empty = server.CreateDatabase("empty");
  try {
    Bank bank(empty);
    FAIL() << "an empty database opened as a bank";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("not a sprite bank (an empty database)"),
              std::string::npos)
        << e.what();
  }
  const std::string unreachable = "postgresql://spritestation@127.0.0.1:1/bank";
  EXPECT_THROW(Bank{unreachable}, BusyError);
}

// Four writers at once (four stations), each its own session and camera, while a reader asks,
// as the transitions worker does, for the clips completed after the last one it saw: ids never
// clash, every clip's complete_seq is unique, and the reader misses none.
TEST(BankPostgres, ManyWritersAtOnceAndAReaderThatMissesNoClip) {
  PostgresServer server;
  ASSERT_TRUE(server.ok());
  const std::string pg = server.CreateDatabase("bank");
  { BankWriter create(pg); }
  constexpr int kWriters = 4, kClips = 12;
  std::atomic<int> done{0};
  std::vector<std::thread> writers;
  writers.reserve(kWriters);
  for (int k = 0; k < kWriters; ++k) {
    writers.emplace_back([&, k] {
      BankWriter w(pg);
      const int64_t session = w.AddSession({0, "station" + std::to_string(k), "s", "", "test"});
      const int64_t camera = w.AddCamera(session, {0, 0, "cam0", "", 640, 480});
      for (int c = 0; c < kClips; ++c) {
        const int64_t first = c * 10;
        w.AppendClipBatch(Clip(camera, c, first, false), MakeBatch(first, first + 2, c));
        w.AppendClipBatch(Clip(camera, c, first, true), MakeBatch(first + 3, first + 4, c));
      }
      done.fetch_add(1);
    });
  }
  std::set<int64_t> seen;
  int64_t last_seq = 0;
  {
    const Bank reader(pg);
    while (true) {
      const bool finished = done.load() == kWriters;
      for (const ClipRecord& c : reader.ListClips(last_seq)) {
        EXPECT_TRUE(seen.insert(c.id).second);
        EXPECT_GT(c.complete_seq, last_seq);
        last_seq = c.complete_seq;
      }
      if (finished) break;
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
  }
  for (auto& t : writers) t.join();
  const Bank bank(pg);
  const BankCounts counts = bank.Counts();
  EXPECT_EQ(counts.sessions, kWriters);
  EXPECT_EQ(counts.clips_complete, kWriters * kClips);
  EXPECT_EQ(counts.sprites, kWriters * kClips * 5 * 2);
  EXPECT_EQ(seen.size(), static_cast<size_t>(kWriters * kClips));
  EXPECT_EQ(last_seq, kWriters * kClips);  // 1..N without a gap
  const auto features = bank.LoadFeatures();
  std::set<int64_t> ids;
  for (const auto& f : features) ids.insert(f.id);
  EXPECT_EQ(ids.size(), features.size());
  EXPECT_TRUE(VerifyBank(pg).ok());
}

// The database host restarts under a writer: the append in between fails as BusyError (worth
// retrying, as the station does) and the same writer goes on once the server is back.
TEST(BankPostgres, AWriterGoesOnAfterTheServerRestarts) {
  PostgresServer server;
  ASSERT_TRUE(server.ok());
  const std::string pg = server.CreateDatabase("bank");
  BankWriter w(pg);
  const Fixture fx = Register(w);
  w.AppendClipBatch(Clip(fx.camera, 1, 0, true), MakeBatch(0, 2, 1));
  server.Stop();
  EXPECT_THROW(w.AppendClipBatch(Clip(fx.camera, 2, 0, true), MakeBatch(0, 2, 2)), BusyError);
  ASSERT_TRUE(server.Start()) << server.log();
  w.AppendClipBatch(Clip(fx.camera, 2, 0, true), MakeBatch(0, 2, 2));
  EXPECT_EQ(Bank(pg).Counts().clips_complete, 2);
  EXPECT_EQ(w.Counts().sprites, 12);
}

TEST(BankPostgres, CopyToPostgresAndBackGivesTheSameBank) {
  PostgresServer server;
  ASSERT_TRUE(server.ok());
  ScratchDir dir;
  const std::string original = dir / "original.db", back = dir / "back.db";
  WriteScenario(original);
  const std::string pg = server.CreateDatabase("copy");
  const BankDigest there = CopyBank(original, pg);
  const BankDigest home = CopyBank(pg, back);
  const BankDigest source = DigestBank(original);
  EXPECT_EQ(there.digest, source.digest);
  EXPECT_EQ(home.digest, source.digest);
  EXPECT_EQ(home.rows, source.rows);
  EXPECT_EQ(source.rows.at("transitions"), 4);  // two, and two kept of four out of one sprite
  EXPECT_TRUE(VerifyBank(pg).ok());
  EXPECT_TRUE(VerifyBank(back).ok());
  EXPECT_EQ(Describe(Bank(back)), Describe(Bank(original)));
  // The copy goes on as a bank: new rows take new ids, not the copied ones.
  BankWriter w(pg);
  const int64_t session = w.AddSession({0, "after-copy", "after", "", "test"});
  EXPECT_GT(session, 2);
  // A copy never merges into a bank that holds sessions.
  EXPECT_THROW(CopyBank(original, pg), InputError);
  // A change on one side changes the digest.
  w.SetMeta("studio", "south");
  EXPECT_NE(DigestBank(pg).digest, DigestBank(original).digest);
}

// The offline optimizer's reads (BankSnapshot) and the bank's one scale (KeepMeta) on both
// backends while another writer goes on.
void SnapshotAndKeptMeta(const std::string& path) {
  BankWriter w(path);
  const Fixture fx = Register(w);
  w.AppendClipBatch(Clip(fx.camera, 1, 0, true), MakeBatch(0, 4, 1));
  w.UpsertTransitions({{w.LoadFeatures()[0].id, w.LoadFeatures()[1].id, 0.5, 0.25}});
  const Bank reader(path);
  {
    const BankSnapshot snapshot(reader);
    const size_t features = reader.LoadFeatures().size();
    // Another writer completes a clip and adds a transition: the snapshot does not see them,
    // also through calls that take a snapshot of their own (Counts).
    w.AppendClipBatch(Clip(fx.camera, 2, 0, true), MakeBatch(0, 4, 2));
    const auto f = w.LoadFeatures();
    w.UpsertTransitions({{f[2].id, f[7].id, 0.75, 0.5}});
    EXPECT_EQ(reader.LoadFeatures().size(), features);
    EXPECT_EQ(reader.LoadTransitions().size(), 1u);
    EXPECT_EQ(reader.Counts().clips_complete, 1);
    EXPECT_EQ(reader.ListClips().size(), 1u);
  }
  EXPECT_EQ(reader.LoadTransitions().size(), 2u);
  EXPECT_EQ(reader.Counts().clips_complete, 2);

  // The first value kept wins; later writers read it back.
  EXPECT_EQ(w.KeepMeta("billboard.px_per_m", "150"), "150");
  BankWriter other(path);
  EXPECT_EQ(other.KeepMeta("billboard.px_per_m", "800"), "150");
  EXPECT_EQ(reader.GetMeta("billboard.px_per_m"), "150");
  EXPECT_THROW(other.KeepMeta("schema_version", "9"), WorkError);

  // A pair given twice in one call keeps its last values (PostgreSQL stores many rows a
  // statement, and one statement may not touch a row twice).
  const auto f = w.LoadFeatures();
  w.UpsertTransitions(
      {{f[3].id, f[8].id, 0.125, 0.5}, {f[4].id, f[8].id, 1, 1}, {f[3].id, f[8].id, 0.25, 0.75}});
  const auto from = reader.LoadTransitionsFrom(f[3].id);
  ASSERT_EQ(from.size(), 1u);
  EXPECT_EQ(from[0].d, 0.25);
  EXPECT_EQ(from[0].cost, 0.75);
}

TEST(BankPostgres, ASnapshotSeesOneStateWhileAnotherWriterGoesOn) {
  PostgresServer server;
  ASSERT_TRUE(server.ok());
  SnapshotAndKeptMeta(server.CreateDatabase("snapshot"));
  ScratchDir dir;
  SnapshotAndKeptMeta(dir / "snapshot.db");  // and the same on SQLite
}

}  // namespace
}  // namespace ss
