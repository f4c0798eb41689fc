// End to end: a synthetic session through `spritestation ingest` into a bank.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "tests/support/test_support.h"

namespace ss {
namespace {

using testing::JsonInOutput;
using testing::RunSpritestation;
using testing::ScratchDir;

class IngestEndToEnd : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new ScratchDir();
    const auto r = RunSpritestation(
        "synth --out " + *dir_ / "session" +
        " --kind animal --seconds 6 --fps 30 --size 480x360 --cameras 2 --subjects 1 --seed 11");
    ASSERT_EQ(r.exit_code, 0) << r.output;
  }
  static void TearDownTestSuite() { delete dir_; }
  static ScratchDir* dir_;
};
ScratchDir* IngestEndToEnd::dir_ = nullptr;

TEST_F(IngestEndToEnd, KeepsUsableSpritesAndCountsEveryDiscard) {
  const std::string bank = *dir_ / "a.bank";
  const auto r = RunSpritestation("--log-level warn ingest " + *dir_ / "session" + " --bank " +
                                  bank + " --json");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const nlohmann::json j = JsonInOutput(r.output);
  ASSERT_TRUE(j.is_object()) << r.output;
  EXPECT_EQ(j["frames"].get<int>(), 2 * 6 * 30);
  EXPECT_GT(j["sprites_kept"].get<int>(), 30) << r.output;
  EXPECT_EQ(j["rows_inserted"].get<int>(),
            2 * j["sprites_kept"].get<int>());  // each with its mirror
  for (const char* reason : {"too_small", "touches_border", "no_ground_hit", "leaves_floor",
                             "touches_wall", "noise", "still", "short_clip"}) {
    EXPECT_TRUE(j["discards"].contains(reason)) << reason;
  }
  ASSERT_EQ(j["cameras"].size(), 2u);
  // One subject: no sprite holds two (docs/pipeline.md, "Merged subjects").
  EXPECT_EQ(j["sprites_merged"].get<int>(), 0) << r.output;
  for (const auto& c : j["cameras"]) EXPECT_EQ(c["sprites_merged"].get<int>(), 0) << r.output;

  const auto info = RunSpritestation("--log-level warn bank info " + bank + " --json");
  ASSERT_EQ(info.exit_code, 0) << info.output;
  const nlohmann::json counts = JsonInOutput(info.output);
  EXPECT_EQ(counts["sprites"].get<int>(), j["rows_inserted"].get<int>()) << info.output;
  EXPECT_EQ(counts["mirrors"].get<int>(), j["sprites_kept"].get<int>()) << info.output;
  const auto verify = RunSpritestation("--log-level warn bank verify " + bank);
  EXPECT_EQ(verify.exit_code, 0) << verify.output;
}

TEST_F(IngestEndToEnd, IngestingTwiceStoresNothingNew) {
  const std::string bank = *dir_ / "b.bank";
  const std::string cmd =
      "--log-level warn ingest " + *dir_ / "session" + " --bank " + bank + " --json";
  const auto first = RunSpritestation(cmd);
  ASSERT_EQ(first.exit_code, 0) << first.output;
  const auto second = RunSpritestation(cmd);
  ASSERT_EQ(second.exit_code, 0) << second.output;
  EXPECT_GT(JsonInOutput(first.output)["rows_inserted"].get<int>(), 0);
  EXPECT_EQ(JsonInOutput(second.output)["rows_inserted"].get<int>(), 0);
  EXPECT_EQ(JsonInOutput(second.output)["sprites_kept"],
            JsonInOutput(first.output)["sprites_kept"]);
}

TEST_F(IngestEndToEnd, BadInputNamesTheFile) {
  const auto missing =
      RunSpritestation("ingest " + *dir_ / "nowhere" + " --bank " + *dir_ / "c.bank");
  EXPECT_EQ(missing.exit_code, 2) << missing.output;
  EXPECT_NE(missing.output.find("nowhere"), std::string::npos) << missing.output;
  const auto no_bank = RunSpritestation("ingest " + *dir_ / "session");
  EXPECT_EQ(no_bank.exit_code, 2) << no_bank.output;
}

// Issue 20: ingest went on writing into a damaged bank. Now a bank that fails SQLite's quick
// check is refused by name before anything is written, and the file is left as it was.
TEST_F(IngestEndToEnd, ADamagedBankIsRefusedAndLeftAsItWas) {
  namespace fs = std::filesystem;
  const std::string bank = *dir_ / "damaged.bank";
  auto r = RunSpritestation("--log-level warn ingest " + *dir_ / "session" + " --bank " + bank +
                            " --no-transitions");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  ASSERT_GT(fs::file_size(bank), 3 * 4096u);
  {
    std::fstream f(bank, std::ios::in | std::ios::out | std::ios::binary);
    f.seekp(2 * 4096);  // page 3: a b-tree page of the schema's first tables
    const std::string garbage(4096, '\xa5');
    f.write(garbage.data(), static_cast<std::streamsize>(garbage.size()));
  }
  const auto before = testing::RunCommand("md5sum < " + bank);
  r = RunSpritestation("--log-level warn ingest " + *dir_ / "session" + " --bank " + bank +
                       " --no-transitions");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find(bank + ": the bank does not pass SQLite's quick check"),
            std::string::npos)
      << r.output;
  EXPECT_NE(r.output.find("bank verify"), std::string::npos) << r.output;
  EXPECT_EQ(testing::RunCommand("md5sum < " + bank).output, before.output);
}

// Issue 39: a bank that reaches its file-size limit (ulimit -f, a quota) killed ingest with
// SIGXFSZ and no word. Now the write fails by name and cause, exit 1; what was committed
// verifies, and the same ingest without the limit completes into the same bank.
TEST_F(IngestEndToEnd, AFileSizeLimitIsAnErrorNamingTheBankAndLosesNothing) {
  const std::string bank = *dir_ / "limited.bank";
  const std::string ingest = testing::SpritestationCommand(
      "--log-level warn ingest " + *dir_ / "session" + " --bank " + bank + " --no-transitions");
  auto r = testing::RunCommand("prlimit --fsize=300000 " + ingest);
  EXPECT_EQ(r.exit_code, 1) << r.output;  // not 128 + SIGXFSZ
  EXPECT_NE(r.output.find(bank + ": "), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("File too large"), std::string::npos) << r.output;
  r = RunSpritestation("bank verify " + bank);
  EXPECT_EQ(r.exit_code, 0) << r.output;
  r = testing::RunCommand(ingest);
  EXPECT_EQ(r.exit_code, 0) << r.output;
  r = RunSpritestation("bank verify " + bank);
  EXPECT_EQ(r.exit_code, 0) << r.output;
}

// Issue 39: a frames CSV cut short (fewer rows than session.json says were recorded) was logged
// as an error while ingest exited 0; a row whose timestamp goes back was reported as "frames
// 10..10 missing from the video". Now the first is a failure named after what was stored, and
// the second names the row and its timestamps.
TEST_F(IngestEndToEnd, ACutOrDisorderedFramesCsvIsAFailureThatSaysWhich) {
  namespace fs = std::filesystem;
  const auto rows = [](const std::string& path) {
    std::ifstream in(path);
    std::vector<std::string> lines;
    for (std::string l; std::getline(in, l);) lines.push_back(l);
    return lines;
  };
  const auto write = [](const std::string& path, const std::vector<std::string>& lines) {
    std::ofstream out(path, std::ios::trunc);
    for (const auto& l : lines) out << l << "\n";
  };
  const std::string cut = *dir_ / "cut";
  fs::copy(*dir_ / "session", cut, fs::copy_options::recursive);
  auto lines = rows(cut + "/cam0.frames.csv");
  ASSERT_GT(lines.size(), 101u);
  lines.resize(101);  // the header and 100 rows of 180
  write(cut + "/cam0.frames.csv", lines);
  auto r = RunSpritestation("--log-level warn ingest " + cut + " --bank " + *dir_ / "cut.bank" +
                            " --no-transitions");
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_NE(r.output.find("ingest stored what it could, but camera cam0: " + cut +
                          "/cam0.frames.csv: lists 100 frames, but the recording was closed "
                          "with 180"),
            std::string::npos)
      << r.output;

  const std::string back = *dir_ / "back";
  fs::copy(*dir_ / "session", back, fs::copy_options::recursive);
  lines = rows(back + "/cam0.frames.csv");
  // row 10 (line 12) takes the time of row 5
  const auto field = [](const std::string& line, int k) {
    size_t a = 0;
    for (int i = 0; i < k; ++i) a = line.find(',', a) + 1;
    return line.substr(a, line.find(',', a) - a);
  };
  const std::string earlier = field(lines[6], 1);
  lines[11] = "10," + earlier + "," + field(lines[11], 2) + "," + field(lines[11], 3);
  write(back + "/cam0.frames.csv", lines);
  r = RunSpritestation("--log-level warn ingest " + back + " --bank " + *dir_ / "back.bank" +
                       " --no-transitions");
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_NE(r.output.find("frame 10 listed in " + back + "/cam0.frames.csv (timestamp_ns " +
                          earlier + ") is missing from the video; row 10's timestamp_ns goes back"),
            std::string::npos)
      << r.output;
}

// A camera whose video cannot be read at all: ingest stores the other camera's sprites, then
// says which camera failed and exits 1 (it used to report success).
TEST_F(IngestEndToEnd, ACameraThatCannotBeReadIsAFailureNamedAfterTheRest) {
  namespace fs = std::filesystem;
  const fs::path damaged = fs::path(*dir_ / "damaged");
  fs::copy(*dir_ / "session", damaged, fs::copy_options::recursive);
  {
    std::ofstream video(damaged / "cam1.mkv", std::ios::trunc | std::ios::binary);
    video << "this is not a Matroska file";
  }
  // Not damaged.bank: the damaged-bank test leaves its corrupt bank there in this suite's folder.
  const std::string bank = *dir_ / "unreadable_camera.bank";
  const auto r = RunSpritestation("--log-level warn ingest " + damaged.string() + " --bank " +
                                  bank + " --json");
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_NE(r.output.find("camera cam1: no frame of it could be read"), std::string::npos)
      << r.output;
  const auto j = JsonInOutput(r.output);
  ASSERT_TRUE(j.contains("cameras")) << r.output;
  int64_t kept_cam0 = -1;
  for (const auto& c : j["cameras"]) {
    if (c["name"] == "cam0") kept_cam0 = c["sprites_kept"].get<int64_t>();
  }
  EXPECT_GT(kept_cam0, 0) << "the readable camera's sprites are stored: " << r.output;
  EXPECT_EQ(j["failed"].size(), 1u) << r.output;
  const auto verify = RunSpritestation("bank verify " + bank);
  EXPECT_EQ(verify.exit_code, 0) << verify.output;
}

// Issue 19: a recording cut short or damaged in the middle. Ingest stores every frame it can
// read (the sprites before the damage, and the other camera's), then exits 1 naming the file
// and the frame, instead of reporting success.
TEST_F(IngestEndToEnd, ATruncatedRecordingIsAFailureNamingTheFileAfterStoringWhatCameBefore) {
  namespace fs = std::filesystem;
  const fs::path damaged = fs::path(*dir_ / "truncated");
  fs::copy(*dir_ / "session", damaged, fs::copy_options::recursive);
  const fs::path video = damaged / "cam0.mkv";
  fs::resize_file(video, fs::file_size(video) * 7 / 10);
  const std::string bank = *dir_ / "truncated.bank";
  const auto r = RunSpritestation("--log-level warn ingest " + damaged.string() + " --bank " +
                                  bank + " --no-transitions --json");
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_NE(r.output.find("camera cam0: "), std::string::npos) << r.output;
  EXPECT_NE(r.output.find(video.string() + ": video ends after "), std::string::npos) << r.output;
  const auto j = JsonInOutput(r.output);
  ASSERT_TRUE(j.contains("cameras")) << r.output;
  for (const auto& c : j["cameras"]) {
    if (c["name"] == "cam0") {
      // The frames before the cut went through the pipeline and their sprites are stored.
      EXPECT_GT(c["frames"].get<int>(), 60) << r.output;
      EXPECT_LT(c["frames"].get<int>(), 180) << r.output;
      EXPECT_GT(c["sprites_kept"].get<int>(), 0) << r.output;
      EXPECT_EQ(c["unreadable_frames"].get<int>(), 180 - c["frames"].get<int>()) << r.output;
    } else {
      EXPECT_EQ(c["frames"].get<int>(), 180) << r.output;
      EXPECT_EQ(c["unreadable_frames"].get<int>(), 0) << r.output;
    }
  }
  EXPECT_EQ(j["failed"].size(), 1u) << r.output;
  const auto info = RunSpritestation("--log-level warn bank info " + bank + " --json");
  ASSERT_EQ(info.exit_code, 0) << info.output;
  EXPECT_EQ(JsonInOutput(info.output)["sprites"].get<int>(), j["rows_inserted"].get<int>())
      << info.output;
  EXPECT_GT(j["rows_inserted"].get<int>(), 0) << r.output;
}

TEST_F(IngestEndToEnd, ACorruptFrameIsAFailureNamingTheFileAndTheFrame) {
  namespace fs = std::filesystem;
  const fs::path damaged = fs::path(*dir_ / "corrupt");
  fs::copy(*dir_ / "session", damaged, fs::copy_options::recursive);
  const fs::path video = damaged / "cam1.mkv";
  {
    // Flip a run of bytes in the middle of the file: inside some frame's data.
    std::fstream file(video, std::ios::in | std::ios::out | std::ios::binary);
    const auto middle = static_cast<std::streamoff>(fs::file_size(video) / 2);
    file.seekg(middle);
    char bytes[16];
    file.read(bytes, sizeof(bytes));
    for (char& b : bytes) b = static_cast<char>(~b);
    file.seekp(middle);
    file.write(bytes, sizeof(bytes));
  }
  const std::string bank = *dir_ / "corrupt.bank";
  const auto r = RunSpritestation("--log-level warn ingest " + damaged.string() + " --bank " +
                                  bank + " --no-transitions --json");
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_NE(r.output.find(" of 180 frames could not be read (" + video.string() + ": frame "),
            std::string::npos)
      << r.output;
  const auto j = JsonInOutput(r.output);
  ASSERT_TRUE(j.contains("cameras")) << r.output;
  for (const auto& c : j["cameras"]) {
    if (c["name"] == "cam1") {
      // Only the damaged frame (or its cluster) is lost; the frames after it are read again.
      EXPECT_GE(c["frames"].get<int>(), 170) << r.output;
      EXPECT_LT(c["frames"].get<int>(), 180) << r.output;
      EXPECT_EQ(c["unreadable_frames"].get<int>(), 180 - c["frames"].get<int>()) << r.output;
    } else {
      EXPECT_EQ(c["frames"].get<int>(), 180) << r.output;
    }
  }
  EXPECT_GT(j["rows_inserted"].get<int>(), 0) << r.output;
}

// A 1080p session recorded in the fast codec (ffvhuff) and in FFV1 is the same footage: both
// decode to the same bytes, so ingest stores the same bank from either; and the FFV1 session
// ingested with one decoder (frames decoded one after another, as before issue 19) stores the
// same bank as with the decoder threads.
TEST(IngestCodecs, FfvhuffAndFfv1GiveTheSameBankWithAnyNumberOfDecoders) {
  ScratchDir dir;
  const std::string common =
      " --kind animal --seconds 5 --fps 10 --size 1920x1080 --cameras 1 --subjects 1 --seed 4"
      " --empty-lead-in 3 --no-mattes --noise 1";
  for (const std::string codec : {"ffv1", "ffvhuff"}) {
    const auto r = RunSpritestation("--log-level warn synth --out " + dir / codec + common +
                                    " --codec " + codec);
    ASSERT_EQ(r.exit_code, 0) << r.output;
  }
  struct Run {
    std::string codec;
    std::string decoders;  // --decode-threads
  };
  const Run runs[] = {{"ffv1", "0"}, {"ffv1", "1"}, {"ffvhuff", "0"}, {"ffvhuff", "1"}};
  std::string digest[4];
  int index = 0;
  for (const Run& run : runs) {
    const std::string session = dir / run.codec;
    const std::string bank = dir / (run.codec + "-" + run.decoders + ".bank");
    auto r = RunSpritestation("--log-level warn ingest " + session + " --bank " + bank +
                              " --no-transitions --json --decode-threads " + run.decoders);
    ASSERT_EQ(r.exit_code, 0) << r.output;
    const nlohmann::json j = JsonInOutput(r.output);
    ASSERT_TRUE(j.is_object()) << r.output;
    EXPECT_GT(j["sprites_kept"].get<int>(), 5) << run.codec << ": " << r.output;
    // Every stored number and every billboard's bytes, in order.
    r = testing::RunCommand(
        "sqlite3 -readonly " + bank +
        " \"SELECT s.frame, s.track_id, s.mirrored, s.ground_x_m, s.ground_y_m, s.mean_r, s.mean_g,"
        " s.mean_b, s.area_px, s.bbox_x, s.bbox_y, s.bbox_w, s.bbox_h, hex(p.data)"
        " FROM sprites s JOIN sprite_pixels p ON p.sprite_id = s.id ORDER BY s.id\"");
    ASSERT_EQ(r.exit_code, 0) << r.output;
    digest[index++] = r.output;
  }
  EXPECT_FALSE(digest[0].empty());
  for (int i = 1; i < 4; ++i) {
    EXPECT_TRUE(digest[0] == digest[i])
        << runs[i].codec << " with --decode-threads " << runs[i].decoders << ": the banks differ ("
        << digest[0].size() << " vs " << digest[i].size() << " bytes of rows)";
  }
}

}  // namespace
}  // namespace ss
