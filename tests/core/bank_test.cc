#include "core/bank.h"

#include <gtest/gtest.h>
#include <signal.h>
#include <sqlite3.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <random>
#include <set>
#include <thread>

#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>

#include "core/bank_export.h"
#include "core/bank_schema.h"
#include "core/bank_verify.h"
#include "core/error.h"
#include "core/sql.h"
#include "tests/support/bank_fixtures.h"
#include "tests/support/test_support.h"

namespace ss {
namespace {

using namespace ss::testing;  // NOLINT: the bank fixtures and ScratchDir

void ExpectSameFields(const SpriteRecord& want, const SpriteRecord& got) {
  EXPECT_EQ(got.frame, want.frame);
  EXPECT_EQ(got.timestamp_ns, want.timestamp_ns);
  EXPECT_EQ(got.mirrored, want.mirrored);
  EXPECT_EQ(got.ground_x_m, want.ground_x_m);
  EXPECT_EQ(got.ground_y_m, want.ground_y_m);
  EXPECT_EQ(got.velocity_x_m_s, want.velocity_x_m_s);
  EXPECT_EQ(got.velocity_y_m_s, want.velocity_y_m_s);
  EXPECT_EQ(got.mean_r, want.mean_r);
  EXPECT_EQ(got.mean_g, want.mean_g);
  EXPECT_EQ(got.mean_b, want.mean_b);
  EXPECT_EQ(got.area_px, want.area_px);
  EXPECT_EQ(got.eccentricity, want.eccentricity);
  EXPECT_EQ(got.bbox_in_image, want.bbox_in_image);
  EXPECT_EQ(got.billboard_width_px, want.billboard_width_px);
  EXPECT_EQ(got.billboard_height_px, want.billboard_height_px);
  EXPECT_EQ(got.px_per_m, want.px_per_m);
  EXPECT_EQ(got.anchor_x_px, want.anchor_x_px);
  EXPECT_EQ(got.anchor_y_px, want.anchor_y_px);
  EXPECT_EQ(got.kind, want.kind);
  EXPECT_EQ(got.heading_rad, want.heading_rad);
  EXPECT_EQ(got.tags, want.tags);
}

TEST(Bank, RoundTripsEveryField) {
  ScratchDir dir;
  const std::string path = dir / "bank.db";
  std::vector<SpriteRecord> batch = MakeBatch(10, 12, 7);
  batch[0].tags = {"run", "walk"};
  batch[1].tags = {"mirror-tag"};
  for (SpriteRecord& s : batch) {  // floor sprites (issue 38), as an overhead camera stores them
    s.kind = SpriteKind::kFloor;
    s.heading_rad = -2.5 + 0.25 * static_cast<double>(s.frame);
  }
  AppendResult result;
  Fixture fx;
  {
    BankWriter w(path);
    fx = Register(w);
    result = w.AppendClipBatch(Clip(fx.camera, 7, 10, true), batch);
    w.UpsertTransitions({{result.sprite_ids[0], result.sprite_ids[2], 0.5, 1.25},
                         {result.sprite_ids[2], result.sprite_ids[4], 0.75, 2.0}});
    w.UpsertTransitions({{result.sprite_ids[0], result.sprite_ids[2], 0.125, 0.25}});  // replaces
    w.SetMeta("transitions_seq", "1");
  }
  ASSERT_EQ(result.sprite_ids.size(), 6u);
  EXPECT_EQ(result.inserted, 6);

  const Bank bank(path);
  EXPECT_EQ(bank.schema_version(), kBankSchemaVersion);
  const auto sessions = bank.ListSessions();
  ASSERT_EQ(sessions.size(), 1u);
  EXPECT_EQ(sessions[0].uid, "synth-a@2024-01-01T00:00:00Z");
  EXPECT_EQ(sessions[0].name, "synth-a");
  EXPECT_EQ(sessions[0].created, "2024-01-01T00:00:00Z");
  EXPECT_EQ(sessions[0].source, "/rec/synth-a");
  const auto cameras = bank.ListCameras();
  ASSERT_EQ(cameras.size(), 1u);
  EXPECT_EQ(cameras[0].session_id, fx.session);
  EXPECT_EQ(cameras[0].name, "cam0");
  EXPECT_EQ(cameras[0].cameramodel, "# mrcal model text\n");
  EXPECT_EQ(cameras[0].width, 1280);
  EXPECT_EQ(cameras[0].height, 720);

  const auto clips = bank.ListClips();
  ASSERT_EQ(clips.size(), 1u);
  EXPECT_EQ(clips[0].id, result.clip_id);
  EXPECT_EQ(clips[0].camera_id, fx.camera);
  EXPECT_EQ(clips[0].track_id, 7);
  EXPECT_EQ(clips[0].first_frame, 10);
  EXPECT_EQ(clips[0].last_frame, 12);
  EXPECT_TRUE(clips[0].complete);
  EXPECT_EQ(clips[0].complete_seq, 1);

  for (size_t i = 0; i < batch.size(); ++i) {
    SCOPED_TRACE(i);
    const SpriteRecord got = bank.LoadSprite(result.sprite_ids[i]);
    ExpectSameFields(batch[i], got);
    EXPECT_EQ(got.id, result.sprite_ids[i]);
    EXPECT_EQ(got.clip_id, result.clip_id);
    EXPECT_EQ(got.camera_id, fx.camera);
    EXPECT_EQ(got.track_id, 7);
    const SpritePixels pixels = bank.LoadPixels(got.id);
    if (batch[i].mirrored) {
      EXPECT_EQ(got.mirror_of, result.sprite_ids[i - 1]);
      cv::Mat flipped_bgra, flipped_shadow;
      cv::flip(batch[i - 1].pixels.bgra, flipped_bgra, 1);
      cv::flip(batch[i - 1].pixels.shadow, flipped_shadow, 1);
      EXPECT_TRUE(SameMat(pixels.bgra, flipped_bgra));
      EXPECT_TRUE(SameMat(pixels.shadow, flipped_shadow));
    } else {
      EXPECT_EQ(got.mirror_of, 0);
      EXPECT_TRUE(SameMat(pixels.bgra, batch[i].pixels.bgra));
      EXPECT_TRUE(SameMat(pixels.shadow, batch[i].pixels.shadow));
    }
  }

  const auto features = bank.LoadFeatures();
  ASSERT_EQ(features.size(), 6u);
  // Ordered by (clip, mirrored, frame): originals 10,11,12 then mirrors 10,11,12.
  for (size_t i = 0; i < 6; ++i) {
    const SpriteFeatures& f = features[i];
    const size_t b = (i % 3) * 2 + (i >= 3 ? 1 : 0);  // index in `batch`
    EXPECT_EQ(f.id, result.sprite_ids[b]);
    EXPECT_EQ(f.frame, batch[b].frame);
    EXPECT_EQ(f.mirrored, batch[b].mirrored);
    EXPECT_EQ(f.timestamp_ns, batch[b].timestamp_ns);
    EXPECT_FLOAT_EQ(f.velocity_x_m_s, static_cast<float>(batch[b].velocity_x_m_s));
    EXPECT_FLOAT_EQ(f.area_px, static_cast<float>(batch[b].area_px));
    EXPECT_FLOAT_EQ(f.mean_b, static_cast<float>(batch[b].mean_b));
    EXPECT_EQ(f.prev, i % 3 == 0 ? -1 : static_cast<int32_t>(i - 1));
    EXPECT_EQ(f.next, i % 3 == 2 ? -1 : static_cast<int32_t>(i + 1));
  }

  const auto transitions = bank.LoadTransitions();
  ASSERT_EQ(transitions.size(), 2u);
  EXPECT_EQ(transitions[0].from_sprite, result.sprite_ids[0]);
  EXPECT_EQ(transitions[0].to_sprite, result.sprite_ids[2]);
  EXPECT_EQ(transitions[0].d, 0.125);
  EXPECT_EQ(transitions[0].cost, 0.25);
  EXPECT_EQ(bank.LoadTransitionsFrom(result.sprite_ids[2]).at(0).cost, 2.0);
  EXPECT_EQ(bank.SpritesTagged("walk"), std::vector<int64_t>{result.sprite_ids[0]});
  EXPECT_EQ(bank.GetMeta("transitions_seq"), "1");
  EXPECT_EQ(bank.GetMeta("nothing"), std::nullopt);

  const BankCounts c = bank.Counts();
  EXPECT_EQ(c.sessions, 1);
  EXPECT_EQ(c.cameras, 1);
  EXPECT_EQ(c.clips, 1);
  EXPECT_EQ(c.sprites, 6);
  EXPECT_EQ(c.mirrors, 3);
  EXPECT_EQ(c.pixel_rows, 3);
  EXPECT_EQ(c.transitions, 2);
  EXPECT_EQ(c.tags, 3);
  EXPECT_EQ(c.tagged_sprites, 2);
  EXPECT_GT(c.file_bytes + c.wal_bytes, 0);
  EXPECT_THROW(bank.LoadSprite(9999), InputError);

  const BankVerifyReport report = VerifyBank(path);
  EXPECT_TRUE(report.ok()) << report.problems.front();
  EXPECT_EQ(report.pixel_blobs_checked, 3);
}

TEST(Bank, ReappendingTheSameSessionAddsNothing) {
  ScratchDir dir;
  const std::string path = dir / "bank.db";
  std::vector<AppendResult> first;
  for (int run = 0; run < 2; ++run) {
    BankWriter w(path);
    const Fixture fx = Register(w);
    EXPECT_EQ(fx.session, 1);
    EXPECT_EQ(fx.camera, 1);
    std::vector<AppendResult> results;
    results.push_back(w.AppendClipBatch(Clip(fx.camera, 1, 0, false), MakeBatch(0, 4, 1)));
    results.push_back(w.AppendClipBatch(Clip(fx.camera, 1, 0, true), MakeBatch(5, 9, 1)));
    results.push_back(w.AppendClipBatch(Clip(fx.camera, 2, 3, true), MakeBatch(3, 6, 2)));
    w.Tag({results[0].sprite_ids[0]}, "keep");
    for (size_t i = 0; i < results.size(); ++i) {
      EXPECT_EQ(results[i].inserted,
                run == 0 ? static_cast<int64_t>(results[i].sprite_ids.size()) : 0);
      if (run == 1) {
        EXPECT_EQ(results[i].clip_id, first[i].clip_id);
        EXPECT_EQ(results[i].sprite_ids, first[i].sprite_ids);
      }
    }
    if (run == 0) first = results;
  }
  const Bank bank(path);
  const BankCounts c = bank.Counts();
  EXPECT_EQ(c.sessions, 1);
  EXPECT_EQ(c.cameras, 1);
  EXPECT_EQ(c.clips, 2);
  EXPECT_EQ(c.sprites, 2 * (10 + 4));
  EXPECT_EQ(c.pixel_rows, 10 + 4);
  EXPECT_EQ(c.tagged_sprites, 1);
  const auto clips = bank.ListClips();
  ASSERT_EQ(clips.size(), 2u);
  EXPECT_EQ(clips[0].complete_seq, 1);
  EXPECT_EQ(clips[1].complete_seq, 2);
  EXPECT_TRUE(VerifyBank(path).ok());
}

TEST(Bank, ReadersSeeOnlyCompleteClips) {
  ScratchDir dir;
  const std::string path = dir / "bank.db";
  BankWriter w(path);
  const Fixture fx = Register(w);
  const Bank reader(path);
  w.AppendClipBatch(Clip(fx.camera, 1, 100, false), MakeBatch(100, 104, 1));
  w.AppendClipBatch(Clip(fx.camera, 2, 0, true), MakeBatch(0, 2, 2));
  EXPECT_EQ(reader.ListClips().size(), 1u);
  EXPECT_EQ(reader.LoadFeatures().size(), 6u);
  EXPECT_EQ(reader.ListAllClips().size(), 2u);
  EXPECT_EQ(reader.ListAllClips()[0].last_frame, 104);

  w.AppendClipBatch(Clip(fx.camera, 1, 100, true), MakeBatch(105, 107, 1));
  const auto clips = reader.ListClips();
  ASSERT_EQ(clips.size(), 2u);
  EXPECT_EQ(clips[1].track_id, 1);
  EXPECT_EQ(clips[1].last_frame, 107);
  EXPECT_EQ(clips[1].complete_seq, 2);
  // The incremental worker's question: what completed after the clips it has seen?
  const auto fresh = reader.LoadFeatures(/*completed_after_seq=*/1);
  ASSERT_EQ(fresh.size(), 16u);
  for (const auto& f : fresh) EXPECT_EQ(f.clip_id, clips[1].id);
  EXPECT_EQ(reader.ListClips(2).size(), 0u);
  // A complete clip does not grow.
  EXPECT_THROW(w.AppendClipBatch(Clip(fx.camera, 1, 100, true), MakeBatch(108, 108, 1)), WorkError);
}

TEST(Bank, ABadBatchIsRejectedWhole) {
  ScratchDir dir;
  const std::string path = dir / "bank.db";
  BankWriter w(path);
  const Fixture fx = Register(w);
  // A mirror whose original is neither in the batch nor in the bank.
  std::vector<SpriteRecord> batch = MakeBatch(0, 3, 1);
  batch.push_back(MakeMirror(MakeSprite(9, 1)));
  EXPECT_THROW(w.AppendClipBatch(Clip(fx.camera, 1, 0, true), batch), WorkError);
  // An original whose pixels do not match its billboard size.
  std::vector<SpriteRecord> wrong = MakeBatch(0, 1, 1);
  wrong[0].pixels = MakePixels(10, 10, 1);
  EXPECT_THROW(w.AppendClipBatch(Clip(fx.camera, 1, 0, true), wrong), WorkError);
  // A sprite before the clip's first frame, and an unknown camera.
  EXPECT_THROW(w.AppendClipBatch(Clip(fx.camera, 1, 5, true), MakeBatch(4, 5, 1)), WorkError);
  EXPECT_THROW(w.AppendClipBatch(Clip(fx.camera + 10, 1, 0, true), MakeBatch(0, 1, 1)), WorkError);
  const BankCounts c = w.Counts();
  EXPECT_EQ(c.clips, 0);
  EXPECT_EQ(c.sprites, 0);
  EXPECT_EQ(c.pixel_rows, 0);
  EXPECT_THROW(w.Tag({12345}, "x"), InputError);
}

TEST(Bank, ReaderIsNotBlockedByAnOpenWriteTransaction) {
  ScratchDir dir;
  const std::string path = dir / "bank.db";
  {
    BankWriter w(path);
    const Fixture fx = Register(w);
    w.AppendClipBatch(Clip(fx.camera, 1, 0, true), MakeBatch(0, 4, 1));
  }
  const Bank reader(path);
  // Another connection holds a write transaction with uncommitted rows.
  sqlite3* db = nullptr;
  ASSERT_EQ(sqlite3_open(path.c_str(), &db), SQLITE_OK);
  ASSERT_EQ(
      sqlite3_exec(db,
                   "BEGIN IMMEDIATE; INSERT INTO sessions (uid) VALUES ('pending');"
                   "DELETE FROM transitions; UPDATE clips SET complete = 0, complete_seq = NULL;",
                   nullptr, nullptr, nullptr),
      SQLITE_OK)
      << sqlite3_errmsg(db);
  const BankCounts during = reader.Counts();  // would fail with SQLITE_BUSY without WAL
  EXPECT_EQ(during.sessions, 1);
  EXPECT_EQ(reader.LoadFeatures().size(), 10u);
  ASSERT_EQ(sqlite3_exec(db, "COMMIT", nullptr, nullptr, nullptr), SQLITE_OK);
  sqlite3_close(db);
  EXPECT_EQ(reader.Counts().sessions, 2);
  EXPECT_EQ(reader.LoadFeatures().size(), 0u);
}

TEST(Bank, ConcurrentReaderDuringWrites) {
  ScratchDir dir;
  const std::string path = dir / "bank.db";
  BankWriter w(path);
  const Fixture fx = Register(w);
  constexpr int kClips = 12, kBatches = 3, kFramesPerBatch = 8;
  std::atomic<int> reads{0};
  std::atomic<bool> writer_done{false};
  std::vector<std::string> reader_errors;
  int64_t last_clips = 0;

  std::thread reader_thread([&] {
    try {
      const Bank reader(path);
      while (true) {
        const bool done = writer_done.load();
        const auto features = reader.LoadFeatures();
        std::map<int64_t, int> per_clip;
        for (const auto& f : features) ++per_clip[f.clip_id];
        for (const auto& [clip, n] : per_clip) {
          if (n != 2 * kBatches * kFramesPerBatch) {
            reader_errors.push_back("clip " + std::to_string(clip) + " visible with " +
                                    std::to_string(n) + " sprites");
          }
        }
        if (static_cast<int64_t>(per_clip.size()) < last_clips)
          reader_errors.push_back("clips went backwards");
        last_clips = static_cast<int64_t>(per_clip.size());
        reads.fetch_add(1);
        if (done) break;
      }
    } catch (const std::exception& e) {
      reader_errors.push_back(e.what());
      reads.store(1 << 30);
    }
  });

  for (int clip = 0; clip < kClips; ++clip) {
    for (int b = 0; b < kBatches; ++b) {
      const int64_t first = b * kFramesPerBatch;
      w.AppendClipBatch(Clip(fx.camera, clip, 0, b == kBatches - 1),
                        MakeBatch(first, first + kFramesPerBatch - 1, clip));
      if (b == 0) {
        // Let the reader read at least once while this clip is half written.
        const int target = reads.load() + 1;
        const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(20);
        while (reads.load() < target && std::chrono::steady_clock::now() < deadline)
          std::this_thread::yield();
      }
    }
  }
  writer_done.store(true);
  reader_thread.join();
  for (const auto& e : reader_errors) ADD_FAILURE() << e;
  EXPECT_GE(reads.load(), kClips);
  EXPECT_EQ(last_clips, kClips);
}

// Child: appends clips of 3 batches each, reporting (track, batch) after every commit, forever.
[[noreturn]] void AppendForever(const std::string& path, int report_fd) {
  try {
    BankWriter w(path);
    const Fixture fx = Register(w);
    for (int32_t track = 0;; ++track) {
      for (int32_t b = 0; b < 3; ++b) {
        w.AppendClipBatch(Clip(fx.camera, track, 0, b == 2), MakeBatch(b * 10, b * 10 + 9, track));
        const int32_t done[2] = {track, b};
        if (write(report_fd, done, sizeof(done)) != sizeof(done)) _exit(4);
      }
    }
  } catch (...) {
    _exit(3);
  }
}

TEST(Bank, WriterKilledMidAppendLeavesEveryCommittedBatch) {
  ScratchDir dir;
  const std::string path = dir / "bank.db";
  int fds[2];
  ASSERT_EQ(pipe(fds), 0);
  const pid_t pid = fork();
  ASSERT_GE(pid, 0);
  if (pid == 0) {
    close(fds[0]);
    AppendForever(path, fds[1]);
  }
  close(fds[1]);
  std::vector<std::pair<int32_t, int32_t>> committed;
  int32_t done[2];
  while (committed.size() < 10 && read(fds[0], done, sizeof(done)) == sizeof(done)) {
    committed.emplace_back(done[0], done[1]);
  }
  ASSERT_EQ(committed.size(), 10u) << "the child writer stopped early";
  kill(pid, SIGKILL);
  int status = 0;
  waitpid(pid, &status, 0);
  ASSERT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == SIGKILL);
  while (read(fds[0], done, sizeof(done)) == sizeof(done)) committed.emplace_back(done[0], done[1]);
  close(fds[0]);

  const BankVerifyReport report = VerifyBank(path);
  EXPECT_TRUE(report.ok()) << report.problems.front();
  for (const auto& [track, b] : committed) {
    const std::string where = " WHERE track_id = " + std::to_string(track) + " AND frame BETWEEN " +
                              std::to_string(b * 10) + " AND " + std::to_string(b * 10 + 9);
    EXPECT_EQ(RawCount(path, "SELECT count(*) FROM sprites" + where), 20)
        << "track " << track << " batch " << b;
  }
  // The batch in flight is all there or not at all.
  const int64_t sprites = RawCount(path, "SELECT count(*) FROM sprites");
  EXPECT_EQ(sprites % 20, 0);
  EXPECT_GE(sprites, static_cast<int64_t>(committed.size()) * 20);
  EXPECT_LE(sprites, static_cast<int64_t>(committed.size() + 1) * 20);
  // Readers see exactly the clips whose last batch committed.
  int64_t complete = 0;
  for (const auto& c : committed) complete += c.second == 2;
  const Bank bank(path);
  EXPECT_GE(static_cast<int64_t>(bank.ListClips().size()), complete);
  EXPECT_LE(static_cast<int64_t>(bank.ListClips().size()), complete + 1);
  // A new writer carries on.
  BankWriter again(path);
  const Fixture fx = Register(again);
  again.AppendClipBatch(Clip(fx.camera, 999, 0, true), MakeBatch(0, 2, 999));
  EXPECT_TRUE(VerifyBank(path).ok());
}

TEST(Bank, WrongSchemaVersionNamesTheFileAndVersions) {
  ScratchDir dir;
  const std::string path = dir / "bank.db";
  { BankWriter w(path); }
  RawExec(path, "PRAGMA user_version = 99");
  for (int writer = 0; writer < 2; ++writer) {
    try {
      if (writer) {
        BankWriter w(path);
      } else {
        Bank b(path);
      }
      ADD_FAILURE() << "opened a bank of schema version 99";
    } catch (const InputError& e) {
      const std::string what = e.what();
      EXPECT_NE(what.find(path), std::string::npos) << what;
      EXPECT_NE(what.find("99"), std::string::npos) << what;
      EXPECT_NE(what.find("expected " + std::to_string(kBankSchemaVersion)), std::string::npos)
          << what;
    }
  }
  EXPECT_THROW(VerifyBank(path), InputError);
}

// Version 3 adds each sprite's kind and heading: a version-2 bank's sprites are all upright.
TEST(Bank, AVersionTwoBanksSpritesAreUprightAfterTheUpgrade) {
  ScratchDir dir;
  const std::string path = dir / "v2.db";
  const auto& migrations = BankMigrations(sql::Dialect::kSqlite);
  RawExec(path, migrations.at(0).sql);
  RawExec(path, migrations.at(1).sql);
  RawExec(path, "PRAGMA application_id = " + std::to_string(kBankApplicationId) +
                    "; PRAGMA user_version = 2; INSERT INTO meta (key, value) VALUES "
                    "('schema_version', '2')");
  RawExec(path,
          "INSERT INTO sessions (id, uid) VALUES (1, 's@t'); "
          "INSERT INTO cameras (id, session_id, name, width, height) VALUES (1, 1, 'cam0', 640, "
          "480); INSERT INTO clips (id, camera_id, track_id, first_frame, last_frame, complete, "
          "complete_seq) VALUES (1, 1, 0, 4, 4, 1, 1); "
          "INSERT INTO sprites (id, clip_id, camera_id, track_id, frame, timestamp_ns, mirrored, "
          "ground_x_m, ground_y_m, velocity_x_m_s, velocity_y_m_s, mean_r, mean_g, mean_b, "
          "area_px, eccentricity, bbox_x, bbox_y, bbox_w, bbox_h, billboard_w_px, billboard_h_px, "
          "px_per_m, anchor_x_px, anchor_y_px) VALUES (1, 1, 1, 0, 4, 133, 0, 0.1, 0.2, 0, 0, 10, "
          "20, 30, 40, 0.5, 1, 2, 3, 4, 5, 6, 800, 2, 5)");
  EXPECT_THROW(Bank b(path), InputError) << "a reader asks for the upgrade";
  { BankWriter w(path); }  // upgrades
  const Bank bank(path);
  EXPECT_EQ(bank.schema_version(), 3);
  const SpriteRecord s = bank.LoadSprite(1);
  EXPECT_EQ(s.kind, SpriteKind::kUpright);
  EXPECT_EQ(s.heading_rad, 0.0);
  EXPECT_EQ(s.ground_y_m, 0.2);
}

TEST(Bank, AVersionOneBankIsUpgradedInPlaceAndKeepsItsSprites) {
  ScratchDir dir;
  const std::string path = dir / "v1.db";
  // A bank as version 1 made it: its migration alone, then one clip.
  RawExec(path, BankMigrations(sql::Dialect::kSqlite).at(0).sql);
  RawExec(path, "PRAGMA application_id = " + std::to_string(kBankApplicationId) +
                    "; PRAGMA user_version = 1; INSERT INTO meta (key, value) VALUES "
                    "('schema_version', '1')");
  EXPECT_THROW(Bank b(path), InputError) << "a reader asks for the upgrade";
  int64_t first = 0;
  {
    BankWriter w(path);  // upgrades
    EXPECT_EQ(w.schema_version(), kBankSchemaVersion);
    const Fixture fx = Register(w);
    first = w.AppendClipBatch(Clip(fx.camera, 1, 0, true), MakeBatch(0, 3, 1)).sprite_ids.at(0);
  }
  EXPECT_TRUE(VerifyBank(path).ok()) << "new and upgraded banks hold the same schema";
  BankWriter w(path);
  w.SetTransitionLabel({first, first + 2, "yes", "2026-12-01T10:00:00Z", "test"});
  w.SetTransitionLabel({first + 2, first, "skip", "2026-12-01T10:00:01Z", "test"});
  w.SetTransitionLabel({first, first + 2, "no", "2026-12-01T10:00:02Z", "test"});  // replaces
  EXPECT_THROW(w.SetTransitionLabel({first, 999999, "yes", "t", "test"}), InputError);
  EXPECT_THROW(w.SetTransitionLabel({first, first + 2, "maybe", "t", "test"}), InputError);
  EXPECT_THROW(w.SetTransitionLabel({first, first, "yes", "t", "test"}), InputError);
  const Bank b(path);
  const auto labels = b.LoadTransitionLabels();
  ASSERT_EQ(labels.size(), 2u);
  EXPECT_EQ(labels[0].label, "skip");
  EXPECT_EQ(labels[1].from_sprite, first);
  EXPECT_EQ(labels[1].label, "no");
  EXPECT_EQ(b.CountTransitionLabels(),
            (std::map<std::string, int64_t>{{"no", 1}, {"skip", 1}, {"yes", 0}}));
  EXPECT_TRUE(w.RemoveTransitionLabel(first + 2, first));
  EXPECT_FALSE(w.RemoveTransitionLabel(first + 2, first));
  EXPECT_EQ(b.LoadTransitionLabels().size(), 1u);
}

TEST(Bank, FilesThatAreNotBanksAreInputErrors) {
  ScratchDir dir;
  const std::string garbage = dir / "garbage.db";
  {
    std::ofstream out(garbage, std::ios::binary);
    std::mt19937 rng(5);
    for (int i = 0; i < 8192; ++i) out.put(static_cast<char>(rng()));
  }
  const std::string other = dir / "other.db";
  RawExec(other, "CREATE TABLE photos (id INTEGER PRIMARY KEY, name TEXT)");
  const std::string empty = dir / "empty.db";
  std::ofstream(empty).close();
  for (const std::string& path : {garbage, other, empty, dir / "missing.db"}) {
    SCOPED_TRACE(path);
    try {
      Bank b(path);
      ADD_FAILURE() << "opened " << path;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
    }
    EXPECT_THROW(VerifyBank(path), InputError);
  }
  // A writer refuses to turn a foreign file into a bank, but starts an empty one.
  EXPECT_THROW(BankWriter w(garbage), InputError);
  EXPECT_THROW(BankWriter w(other), InputError);
  BankWriter w(empty);
  EXPECT_EQ(w.schema_version(), kBankSchemaVersion);
}

TEST(Bank, VerifyFindsEachKindOfDamage) {
  struct Damage {
    const char* name;
    const char* sql;
    const char* expect;  // a word the problem report must contain
  };
  const Damage damages[] = {
      // a frame header that states no size (it was reported as 18446744073709551615 bytes)
      {"pixel blob", "UPDATE sprite_pixels SET data = x'28b52ffd0000' WHERE sprite_id = 1",
       "states no size"},
      {"pixel size", "UPDATE sprite_pixels SET width_px = 8 WHERE sprite_id = 1", "pixels"},
      {"mirror speed", "UPDATE sprites SET velocity_x_m_s = 5 WHERE mirrored = 1 AND frame = 2",
       "mirror"},
      {"clip range", "UPDATE clips SET last_frame = last_frame + 3 WHERE complete = 1", "clip"},
      {"lost sprite", "DELETE FROM sprites WHERE mirrored = 0 AND frame = 3 AND track_id = 1",
       "clip"},
      {"foreign key", "PRAGMA foreign_keys = OFF; DELETE FROM clips WHERE complete = 0",
       "foreign key"},
      {"schema", "DROP INDEX sprites_by_clip", "schema"},
  };
  for (const Damage& d : damages) {
    SCOPED_TRACE(d.name);
    ScratchDir dir;
    const std::string path = dir / "bank.db";
    SmallBank(path);
    ASSERT_TRUE(VerifyBank(path).ok());
    RawExec(path, d.sql);
    const BankVerifyReport r = VerifyBank(path);
    ASSERT_FALSE(r.ok());
    bool found = false;
    for (const auto& p : r.problems) found = found || p.find(d.expect) != std::string::npos;
    EXPECT_TRUE(found) << r.problems.front();
  }
}

TEST(Bank, VerifyFindsDamagedPages) {
  ScratchDir dir;
  const std::string path = dir / "bank.db";
  SmallBank(path);  // the writer's close checkpoints the WAL into the file
  const auto size = std::filesystem::file_size(path);
  ASSERT_GT(size, 8192u);
  {
    std::fstream f(path, std::ios::in | std::ios::out | std::ios::binary);
    f.seekp(static_cast<std::streamoff>(size / 2));
    for (int i = 0; i < 4096; ++i) f.put(static_cast<char>(0xA5));
  }
  const BankVerifyReport r = VerifyBank(path);
  EXPECT_FALSE(r.ok());
}

}  // namespace
}  // namespace ss
