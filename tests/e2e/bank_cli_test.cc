// `spritestation bank ...` as a user runs it: info, verify, tag, export, and
// files that are not banks (the executable, so in tests/e2e).
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>

#include "core/bank.h"
#include "core/bank_schema.h"
#include "core/bank_verify.h"
#include "tests/support/bank_fixtures.h"
#include "tests/support/test_support.h"

namespace ss {
namespace {

using namespace ss::testing;  // NOLINT: the bank fixtures, ScratchDir, RunSpritestation

TEST(BankCli, InfoJsonReportsTheCounts) {
  ScratchDir dir;
  const std::string path = dir / "bank.db";
  const int64_t sprite = SmallBank(path);
  { BankWriter(path).Tag({sprite}, "hero"); }
  const auto r = RunSpritestation("bank info " + path + " --json");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const auto j = nlohmann::json::parse(r.output);
  EXPECT_EQ(j["schema_version"], kBankSchemaVersion);
  EXPECT_EQ(j["sessions"], 1);
  EXPECT_EQ(j["cameras"], 1);
  EXPECT_EQ(j["clips"], 2);
  EXPECT_EQ(j["clips_complete"], 1);
  EXPECT_EQ(j["sprites"], 16);
  EXPECT_EQ(j["mirrors"], 8);
  EXPECT_EQ(j["sprites_visible"], 12);
  EXPECT_EQ(j["tags"], 1);
  EXPECT_EQ(j["transitions"], 0);
  EXPECT_GT(j["file_bytes"].get<int64_t>(), 0);
}

TEST(BankCli, VerifyExitCodes) {
  ScratchDir dir;
  const std::string good = dir / "good.db";
  SmallBank(good);
  auto r = RunSpritestation("bank verify " + good);
  EXPECT_EQ(r.exit_code, 0) << r.output;
  r = RunSpritestation("bank verify " + good + " --json");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_EQ(nlohmann::json::parse(r.output)["ok"], true);

  const std::string damaged = dir / "damaged.db";
  SmallBank(damaged);
  RawExec(damaged, "UPDATE sprite_pixels SET data = x'00010203' WHERE sprite_id = 1");
  r = RunSpritestation("bank verify " + damaged);
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_NE(r.output.find("sprite 1"), std::string::npos) << r.output;

  const std::string newer = dir / "newer.db";
  SmallBank(newer);
  RawExec(newer, "PRAGMA user_version = 7");
  r = RunSpritestation("bank verify " + newer);
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find(newer), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("version 7"), std::string::npos) << r.output;

  const std::string text = dir / "notes.txt";
  std::ofstream(text) << "not a bank, just some notes that are long enough to fill a header page\n";
  r = RunSpritestation("bank verify " + text);
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find(text), std::string::npos) << r.output;
  r = RunSpritestation("bank info " + text);
  EXPECT_EQ(r.exit_code, 2) << r.output;
}

TEST(BankCli, TagAndExport) {
  ScratchDir dir;
  const std::string path = dir / "bank.db";
  const int64_t sprite = SmallBank(path);
  auto r = RunSpritestation("bank tag " + path + " --sprites " + std::to_string(sprite) + "," +
                            std::to_string(sprite + 1) + " --tag hero");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_EQ(Bank(path).SpritesTagged("hero").size(), 2u);
  r = RunSpritestation("bank tag " + path + " --sprites 4242 --tag hero");
  EXPECT_EQ(r.exit_code, 2) << r.output;

  const std::string out = dir / "export";
  r = RunSpritestation("bank export " + path + " --out " + out + " --json");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_EQ(nlohmann::json::parse(r.output)["sprites"], 12);
  const cv::Mat png =
      cv::imread(out + "/sprite_" + std::to_string(sprite) + ".png", cv::IMREAD_UNCHANGED);
  EXPECT_TRUE(SameMat(png, Bank(path).LoadPixels(sprite).bgra));
  std::ifstream csv(out + "/sprites.csv");
  int lines = 0;
  for (std::string line; std::getline(csv, line);) ++lines;
  EXPECT_EQ(lines, 1 + 12);
}

std::string FileBytesOf(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

// The JSON report inside a command's output (log lines and the error line come after it).
nlohmann::json JsonIn(const std::string& output) {
  const size_t begin = output.find("{\n");
  const size_t end = output.find("\n}", begin);
  if (begin == std::string::npos || end == std::string::npos) return nullptr;
  return nlohmann::json::parse(output.substr(begin, end + 2 - begin));
}

TEST(BankCli, EveryCommandRefusesFilesThatAreNotBanksAndChangesNothing) {
  ScratchDir dir;
  const std::string empty = dir / "empty.db";
  std::ofstream(empty).close();
  const std::string newer = dir / "newer.db";
  SmallBank(newer);
  RawExec(newer, "PRAGMA user_version = 7");
  const std::string text = dir / "notes.txt";
  std::ofstream(text) << "not a bank, just some notes that are long enough to fill a header page\n";
  for (const std::string& path : {empty, newer, text}) {
    SCOPED_TRACE(path);
    const std::string before = FileBytesOf(path);
    for (const std::string& command :
         {"bank info " + path + " --json", "bank verify " + path + " --json",
          "bank tag " + path + " --sprites 1 --tag hero",
          "bank export " + path + " --out " + (dir / "out") + " --json"}) {
      const auto r = RunSpritestation(command);
      EXPECT_EQ(r.exit_code, 2) << command << "\n" << r.output;
      EXPECT_NE(r.output.find("spritestation: error: " + path + ": "), std::string::npos)
          << command << "\n"
          << r.output;
    }
    EXPECT_EQ(FileBytesOf(path), before)
        << "the file was changed";  // an empty file did not become a bank
  }
  EXPECT_FALSE(std::filesystem::exists((dir / "out") + "/sprites.csv"));
  const auto r = RunSpritestation("bank info " + (dir / "missing.db"));
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find((dir / "missing.db") + ": no such sprite bank"), std::string::npos)
      << r.output;
  EXPECT_FALSE(std::filesystem::exists(dir / "missing.db"));
}

TEST(BankCli, DamagedPagesAreReportedNotHidden) {
  ScratchDir dir;
  const std::string path = dir / "bank.db";
  SmallBank(path);
  const auto size = std::filesystem::file_size(path);
  {
    // Overwrite every page after the first two: the sprites and pixels live there.
    std::fstream f(path, std::ios::in | std::ios::out | std::ios::binary);
    f.seekp(8192);
    for (uintmax_t i = 8192; i < size; ++i) f.put(static_cast<char>(0xA5));
  }
  auto r = RunSpritestation("bank verify " + path + " --json");
  EXPECT_EQ(r.exit_code, 1) << r.output;  // a bank, damaged
  const auto j = JsonIn(r.output);
  ASSERT_TRUE(j.is_object()) << r.output;
  EXPECT_EQ(j["ok"], false);
  EXPECT_FALSE(j["problems"].empty());
  EXPECT_NE(r.output.find(path), std::string::npos) << r.output;
  r = RunSpritestation("bank info " + path);
  EXPECT_EQ(r.exit_code, 2) << r.output;  // bad input, named
  EXPECT_NE(r.output.find(path + ": the database is damaged"), std::string::npos) << r.output;
}

// A bank that opens but fails SQLite's quick check (a damaged page of its first tables) is
// written into by nothing: each writing command refuses it as ingest does, names the file and
// the way to see the damage, and leaves every byte as it was (issue 39: `bank tag` wrote).
TEST(BankCli, WritingCommandsRefuseABankThatFailsItsQuickCheck) {
  ScratchDir dir;
  const std::string path = dir / "bank.db";
  SmallBank(path);
  ASSERT_TRUE(QuickCheckBank(path).empty());
  ASSERT_GT(std::filesystem::file_size(path), 3 * 4096u);
  {
    std::fstream f(path, std::ios::in | std::ios::out | std::ios::binary);
    f.seekp(2 * 4096);  // page 3: a b-tree page of the schema's first tables
    const std::string garbage(4096, '\xa5');
    f.write(garbage.data(), static_cast<std::streamsize>(garbage.size()));
  }
  ASSERT_FALSE(QuickCheckBank(path).empty());
  const auto before = RunCommand("md5sum < " + path).output;
  for (const std::string& command : {"bank tag " + path + " --sprites 1 --tag stand",
                                     "bank upgrade " + path, "transitions " + path + " --quiet"}) {
    SCOPED_TRACE(command);
    const auto r = RunSpritestation(command);
    EXPECT_EQ(r.exit_code, 2) << r.output;
    EXPECT_NE(r.output.find(path + ": the bank does not pass SQLite's quick check"),
              std::string::npos)
        << r.output;
    EXPECT_NE(r.output.find("spritestation bank verify " + path), std::string::npos) << r.output;
    EXPECT_EQ(RunCommand("md5sum < " + path).output, before);
  }
}

// Issue 39: what a command prints must arrive, or it fails saying so (exit 1), not exit 0 with
// a reader left holding a cut-off listing.
TEST(BankCli, AStandardOutputThatCannotBeWrittenIsAFailure) {
  ScratchDir dir;
  const std::string path = dir / "bank.db";
  SmallBank(path);
  const auto r =
      RunCommand("{ " + SpritestationCommand("bank info " + path) +
                 " > /dev/full; }");  // (RunCommand sends the group's stderr to the pipe)
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_NE(r.output.find("standard output: No space left on device"), std::string::npos)
      << r.output;
}

TEST(BankCli, TagRemoveAndJson) {
  ScratchDir dir;
  const std::string path = dir / "bank.db";
  const int64_t sprite = SmallBank(path);
  auto r = RunSpritestation("bank tag " + path + " --sprites " + std::to_string(sprite) +
                            " --tag walk --json");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  auto j = JsonIn(r.output);
  EXPECT_EQ(j["sprites_with_tag"], 1);
  EXPECT_EQ(Bank(path).LoadSprite(sprite).tags, std::vector<std::string>{"walk"});
  r = RunSpritestation("bank tag " + path + " --sprites " + std::to_string(sprite) +
                       " --tag walk --remove --json");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_EQ(JsonIn(r.output)["sprites_with_tag"], 0);
  EXPECT_TRUE(Bank(path).LoadSprite(sprite).tags.empty());
  // An unknown id rejects the whole call: the known one is not tagged either.
  r = RunSpritestation("bank tag " + path + " --sprites " + std::to_string(sprite) +
                       ",4242 --tag walk");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find(path + ": no sprite with id 4242"), std::string::npos) << r.output;
  EXPECT_TRUE(Bank(path).SpritesTagged("walk").empty());
  // Export by tag writes only those sprites.
  BankWriter(path).Tag({sprite}, "hero");
  r = RunSpritestation("bank export " + path + " --out " + (dir / "hero") + " --tag hero --json");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_EQ(JsonIn(r.output)["sprites"], 1);
  EXPECT_TRUE(
      std::filesystem::exists((dir / "hero") + "/sprite_" + std::to_string(sprite) + ".png"));
  EXPECT_TRUE(VerifyBank(path).ok());
}

}  // namespace
}  // namespace ss
