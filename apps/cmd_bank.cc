// spritestation bank info|verify|tag|export|upgrade|digest BANK, bank copy FROM TO: inspect,
// maintain and move a sprite bank (a SQLite file or a postgresql:// address).
#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "apps/commands.h"
#include "core/bank.h"
#include "core/bank_copy.h"
#include "core/bank_export.h"
#include "core/bank_schema.h"
#include "core/bank_verify.h"
#include "core/error.h"
#include "core/sql_postgres.h"

namespace ss::apps {
namespace {

std::string Megabytes(int64_t bytes) {
  char buffer[32];
  if (bytes < 1'000'000) {
    std::snprintf(buffer, sizeof(buffer), "%.1f kB", static_cast<double>(bytes) / 1e3);
  } else {
    std::snprintf(buffer, sizeof(buffer), "%.1f MB", static_cast<double>(bytes) / 1e6);
  }
  return buffer;
}

void Info(const std::string& address, bool json) {
  const Bank bank(address);
  const std::string& path = bank.path();  // without a password
  const BankCounts c = bank.Counts();
  if (json) {
    nlohmann::json j = {{"bank", path},
                        {"schema_version", c.schema_version},
                        {"sessions", c.sessions},
                        {"cameras", c.cameras},
                        {"clips", c.clips},
                        {"clips_complete", c.clips_complete},
                        {"sprites", c.sprites},
                        {"mirrors", c.mirrors},
                        {"sprites_visible", c.sprites_visible},
                        {"pixel_rows", c.pixel_rows},
                        {"pixel_bytes", c.pixel_bytes},
                        {"transitions", c.transitions},
                        {"tags", c.tags},
                        {"tagged_sprites", c.tagged_sprites},
                        {"file_bytes", c.file_bytes},
                        {"wal_bytes", c.wal_bytes}};
    std::printf("%s\n", j.dump(2).c_str());
    return;
  }
  std::printf("bank:           %s\n", path.c_str());
  std::printf("schema version: %d\n", c.schema_version);
  std::printf("sessions:       %lld (%lld cameras)\n", static_cast<long long>(c.sessions),
              static_cast<long long>(c.cameras));
  std::printf("clips:          %lld (%lld complete)\n", static_cast<long long>(c.clips),
              static_cast<long long>(c.clips_complete));
  std::printf("sprites:        %lld (%lld of them mirrors; %lld in complete clips)\n",
              static_cast<long long>(c.sprites), static_cast<long long>(c.mirrors),
              static_cast<long long>(c.sprites_visible));
  std::printf("billboards:     %lld, %s compressed\n", static_cast<long long>(c.pixel_rows),
              Megabytes(c.pixel_bytes).c_str());
  std::printf("transitions:    %lld\n", static_cast<long long>(c.transitions));
  std::printf("tags:           %lld names on %lld sprites\n", static_cast<long long>(c.tags),
              static_cast<long long>(c.tagged_sprites));
  if (bank.is_postgres()) {
    std::printf("on the server:  %s (tables, indexes and their out-of-line data)\n",
                Megabytes(c.file_bytes).c_str());
  } else {
    std::printf("file:           %s (+ %s write-ahead log)\n", Megabytes(c.file_bytes).c_str(),
                Megabytes(c.wal_bytes).c_str());
  }
}

void Verify(const std::string& address, bool json) {
  const BankVerifyReport r = VerifyBank(address);
  const std::string& path = r.path;  // without a password
  if (json) {
    nlohmann::json j = {{"bank", path},
                        {"ok", r.ok()},
                        {"schema_version", r.schema_version},
                        {"clips_checked", r.clips_checked},
                        {"sprites_checked", r.sprites_checked},
                        {"pixel_blobs_checked", r.pixel_blobs_checked},
                        {"problems", r.problems}};
    std::printf("%s\n", j.dump(2).c_str());
  } else if (r.ok()) {
    std::printf("%s: ok (schema version %d; %lld clips, %lld sprites, %lld billboards checked)\n",
                path.c_str(), r.schema_version, static_cast<long long>(r.clips_checked),
                static_cast<long long>(r.sprites_checked),
                static_cast<long long>(r.pixel_blobs_checked));
  } else {
    for (const auto& p : r.problems) std::printf("%s: %s\n", path.c_str(), p.c_str());
  }
  if (!r.ok()) {
    throw WorkError(path, "the bank is damaged (" + std::to_string(r.problems.size()) +
                              " problems; first: " + r.problems.front() + ")");
  }
}

}  // namespace

void AddBankCommand(CLI::App& app) {
  auto* bank = app.add_subcommand("bank", "Inspect and maintain a sprite bank");
  bank->require_subcommand(1);

  struct Args {
    std::string path, out, tag;
    std::vector<int64_t> sprites;
    bool json = false, remove = false, no_mirrors = false;
  };
  auto args = std::make_shared<Args>();

  auto* info = bank->add_subcommand(
      "info", "Counts: sessions, cameras, clips, sprites, transitions, tags, size");
  info->add_option("bank", args->path, "Sprite bank (file or postgresql://...)")->required();
  info->add_flag("--json", args->json, "Print JSON");
  info->callback([args] { Info(args->path, args->json); });

  auto* verify = bank->add_subcommand("verify",
                                      "Check integrity, schema and invariants; exit 1 when "
                                      "damaged, 2 when not a bank of this version");
  verify->add_option("bank", args->path, "Sprite bank (file or postgresql://...)")->required();
  verify->add_flag("--json", args->json, "Print JSON");
  verify->callback([args] { Verify(args->path, args->json); });

  auto* tag = bank->add_subcommand("tag", "Add (or --remove) a tag on sprites");
  tag->add_option("bank", args->path, "Sprite bank (file or postgresql://...)")->required();
  tag->add_option("--sprites", args->sprites, "Sprite ids, comma-separated")
      ->required()
      ->delimiter(',');
  tag->add_option("--tag", args->tag, "Tag name")->required();
  tag->add_flag("--remove", args->remove, "Remove the tag instead");
  tag->add_flag("--json", args->json, "Print JSON");
  tag->callback([args] {
    // Opened read-only first: the writer would turn an empty file into a new bank
    // and upgrade an older one in place; tagging does neither.
    { const Bank check(args->path); }
    RefuseDamagedBank(args->path);
    BankWriter writer(args->path);
    if (args->remove) {
      writer.Untag(args->sprites, args->tag);
    } else {
      writer.Tag(args->sprites, args->tag);
    }
    const size_t total = writer.SpritesTagged(args->tag).size();
    if (args->json) {
      std::printf("%s\n", nlohmann::json({{"tag", args->tag},
                                          {"removed", args->remove},
                                          {"sprites", args->sprites},
                                          {"sprites_with_tag", total}})
                              .dump(2)
                              .c_str());
    } else {
      std::printf("%s '%s' on %zu sprites; %zu sprites now carry it\n",
                  args->remove ? "removed" : "tagged", args->tag.c_str(), args->sprites.size(),
                  total);
    }
  });

  auto* exp =
      bank->add_subcommand("export", "Write the visible sprites as PNG billboards and sprites.csv");
  exp->add_option("bank", args->path, "Sprite bank (file or postgresql://...)")->required();
  exp->add_option("--out", args->out, "Output folder")->required();
  exp->add_option("--tag", args->tag, "Only sprites with this tag");
  exp->add_flag("--no-mirrors", args->no_mirrors, "Leave out the mirrored copies");
  exp->add_flag("--json", args->json, "Print JSON");
  exp->callback([args] {
    const Bank bank(args->path);
    const int64_t n = ExportBank(bank, args->out, {args->tag, !args->no_mirrors});
    if (args->json) {
      std::printf("%s\n", nlohmann::json({{"out", args->out}, {"sprites", n}}).dump(2).c_str());
    } else {
      std::printf("%lld sprites written to %s\n", static_cast<long long>(n), args->out.c_str());
    }
  });

  auto* upgrade = bank->add_subcommand("upgrade", "Upgrade an older bank's schema in place");
  upgrade->add_option("bank", args->path, "Sprite bank (file or postgresql://...)")->required();
  upgrade->add_flag("--json", args->json, "Print JSON");
  upgrade->callback([args] {
    if (!sql::IsPostgresAddress(args->path) && !std::filesystem::exists(args->path)) {
      throw InputError(args->path, "no such sprite bank");
    }
    RefuseDamagedBank(args->path);
    const BankWriter writer(args->path);
    if (args->json) {
      std::printf("%s\n", nlohmann::json({{"bank", writer.path()},
                                          {"schema_version", writer.schema_version()}})
                              .dump(2)
                              .c_str());
    } else {
      std::printf("%s: schema version %d (current %d)\n", writer.path().c_str(),
                  writer.schema_version(), kBankSchemaVersion);
    }
  });

  auto* copy = bank->add_subcommand(
      "copy",
      "Copy a bank into an empty one, keeping every id: SQLite to PostgreSQL or back (verified)");
  copy->add_option("from", args->path, "Sprite bank to copy (file or postgresql://...)")
      ->required();
  copy->add_option("to", args->out,
                   "Empty or new sprite bank to copy into (file or postgresql://...)")
      ->required();
  copy->add_flag("--json", args->json, "Print JSON");
  copy->callback([args] {
    const BankDigest d = CopyBank(args->path, args->out);
    const BankVerifyReport r = VerifyBank(args->out);
    if (!r.ok()) throw WorkError(r.path, "the copy does not verify: " + r.problems.front());
    int64_t rows = 0;
    for (const auto& [table, n] : d.rows) rows += n;
    if (args->json) {
      std::printf("%s\n", nlohmann::json({{"from", sql::RedactAddress(args->path)},
                                          {"to", r.path},
                                          {"digest", d.digest},
                                          {"rows", d.rows},
                                          {"verified", true}})
                              .dump(2)
                              .c_str());
    } else {
      std::printf(
          "copied %lld rows (%lld sprites, %lld transitions) into %s: digest %s on both sides, "
          "verified\n",
          static_cast<long long>(rows), static_cast<long long>(d.rows.at("sprites")),
          static_cast<long long>(d.rows.at("transitions")), r.path.c_str(), d.digest.c_str());
    }
  });

  auto* digest = bank->add_subcommand(
      "digest", "A digest of the bank's content, the same in SQLite and PostgreSQL");
  digest->add_option("bank", args->path, "Sprite bank (file or postgresql://...)")->required();
  digest->add_flag("--json", args->json, "Print JSON");
  digest->callback([args] {
    const BankDigest d = DigestBank(args->path);
    if (args->json) {
      std::printf("%s\n", nlohmann::json({{"digest", d.digest}, {"rows", d.rows}}).dump(2).c_str());
    } else {
      std::printf("%s\n", d.digest.c_str());
    }
  });
}

}  // namespace ss::apps
