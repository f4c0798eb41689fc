// End to end on a PostgreSQL bank (issue 21): `ingest`, `transitions`, `bank info / verify /
// digest / copy` take `postgresql://` addresses as they take files, and give the same bank.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "tests/support/postgres_server.h"
#include "tests/support/test_support.h"

namespace ss {
namespace {

using testing::JsonInOutput;
using testing::PostgresServer;
using testing::RunSpritestation;
using testing::ScratchDir;

nlohmann::json Json(const std::string& args) {
  const auto r = RunSpritestation("--log-level warn " + args + " --json");
  EXPECT_EQ(r.exit_code, 0) << args << "\n" << r.output;
  return JsonInOutput(r.output);
}

TEST(BankPostgresCli, IngestTransitionsAndCopyGiveTheSameBankAsAFile) {
  PostgresServer server;
  ASSERT_TRUE(server.ok());
  ScratchDir dir;
  const auto synth = RunSpritestation(
      "synth --out " + dir / "session" +
      " --kind animal --seconds 5 --fps 30 --size 480x360 --cameras 1 --subjects 1 "
      "--seed 5");
  ASSERT_EQ(synth.exit_code, 0) << synth.output;
  const std::string file = dir / "bank.db", back = dir / "back.db";
  const std::string pg = server.CreateDatabase("studio");

  const nlohmann::json a = Json("ingest " + dir / "session" + " --bank " + file);
  const nlohmann::json b = Json("ingest " + dir / "session" + " --bank " + pg);
  ASSERT_GT(a["sprites_kept"].get<int>(), 20);
  EXPECT_EQ(b["sprites_kept"], a["sprites_kept"]);
  EXPECT_EQ(b["rows_inserted"], a["rows_inserted"]);
  EXPECT_EQ(b["transitions_stored"], a["transitions_stored"]);
  ASSERT_GT(a["transitions_stored"].get<int>(), 0);

  const nlohmann::json fa = Json("bank info " + file), fb = Json("bank info " + pg);
  for (const char* key : {"sessions", "cameras", "clips_complete", "sprites", "mirrors",
                          "pixel_rows", "pixel_bytes", "transitions"}) {
    EXPECT_EQ(fb[key], fa[key]) << key;
  }
  // A full rebuild of the transitions from the PostgreSQL bank finds the same table.
  EXPECT_EQ(Json("transitions " + pg)["transitions"], a["transitions_stored"]);
  EXPECT_TRUE(Json("bank verify " + pg)["ok"].get<bool>());

  // PostgreSQL -> SQLite keeps every id and byte: the digests agree, and so does the file's count.
  const nlohmann::json copied = Json("bank copy " + pg + " " + back);
  EXPECT_TRUE(copied["verified"].get<bool>());
  EXPECT_EQ(Json("bank digest " + back)["digest"], Json("bank digest " + pg)["digest"]);
  EXPECT_EQ(Json("bank info " + back)["transitions"], fa["transitions"]);

  // Copying into a bank that holds sessions is refused (exit 2), naming it without its password.
  const std::string with_password =
      "postgresql://spritestation:s3cret@127.0.0.1:" + std::to_string(server.port()) + "/studio";
  const auto refused = RunSpritestation("--log-level warn bank copy " + file + " " + with_password);
  EXPECT_EQ(refused.exit_code, 2) << refused.output;
  EXPECT_NE(refused.output.find("holds sessions already"), std::string::npos) << refused.output;
  EXPECT_EQ(refused.output.find("s3cret"), std::string::npos) << refused.output;
}

}  // namespace
}  // namespace ss
