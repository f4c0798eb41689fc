#include "core/bank_verify.h"

#include <algorithm>

#include <sqlite3.h>

#include <cmath>
#include <filesystem>
#include <functional>
#include <map>

#include "core/bank_pixels.h"
#include "core/bank_schema.h"
#include "core/error.h"
#include "core/sql.h"
#include "core/sql_postgres.h"
#include "core/sql_sqlite.h"

namespace ss {
namespace {

// Examples listed per kind of problem before the rest is summarized as a count.
constexpr int kMaxExamples = 10;

class Checker {
 public:
  Checker(const sql::Db& db, BankVerifyReport& report) : db_(db), report_(report) {}

  // Runs one check; an SQLite error inside it (a damaged page) is itself a problem.
  void Run(const std::string& name, const std::function<void()>& check) {
    try {
      check();
    } catch (const std::exception& e) {
      report_.problems.push_back(name + ": could not be checked (" + e.what() + ")");
    }
  }

  // Each row of `query` is one problem; its first column is the description.
  void Rows(const std::string& kind, const std::string& query) {
    auto s = db_.Prepare(query);
    int64_t n = 0;
    while (s.Step()) {
      if (n++ < kMaxExamples) report_.problems.push_back(kind + ": " + s.Text(0));
    }
    if (n > kMaxExamples)
      report_.problems.push_back(kind + ": " + std::to_string(n - kMaxExamples) + " more");
  }

  void Add(const std::string& problem) { report_.problems.push_back(problem); }

 private:
  const sql::Db& db_;
  BankVerifyReport& report_;
};

void CheckSchema(const sql::Db& db, Checker& check) {
  const int64_t version = db.QueryInt("PRAGMA user_version");
  auto meta = db.Prepare("SELECT value FROM meta WHERE key = 'schema_version'");
  const std::string stored = meta.Step() ? meta.Text(0) : "(missing)";
  if (stored != std::to_string(version)) {
    check.Add("schema: meta.schema_version is " + stored + " but PRAGMA user_version is " +
              std::to_string(version));
  }
  auto journal = db.Prepare("PRAGMA journal_mode");
  const std::string mode = journal.Step() ? journal.Text(0) : "";
  if (mode != "wal") check.Add("schema: journal_mode is '" + mode + "', expected 'wal'");

  std::map<std::string, SchemaObject> found;
  for (auto& o : ReadSchema(db)) found[o.type + " " + o.name] = o;
  for (const auto& want : ExpectedSchema()) {
    const auto it = found.find(want.type + " " + want.name);
    if (it == found.end()) {
      check.Add("schema: " + want.type + " '" + want.name + "' is missing");
    } else if (it->second.sql != want.sql) {
      check.Add("schema: " + want.type + " '" + want.name + "' differs from schema version " +
                std::to_string(kBankSchemaVersion) + ": " + it->second.sql);
    }
  }
}

// PostgreSQL: every table, column and index that the current schema version defines is there
// (the same names as SQLite's; their types are PostgreSQL's, set by the migrations).
void CheckPostgresSchema(const sql::Db& db, Checker& check) {
  const int version = ReadSchemaVersion(db);
  if (version != kBankSchemaVersion) {
    check.Add("schema: meta.schema_version is " + std::to_string(version) + ", expected " +
              std::to_string(kBankSchemaVersion));
  }
  sql::Db reference =
      sql::OpenSqlite(":memory:", SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE | SQLITE_OPEN_MEMORY);
  for (const auto& m : BankMigrations(sql::Dialect::kSqlite)) reference.Exec(m.sql);
  auto columns = db.Prepare(
      "SELECT column_name FROM information_schema.columns "
      "WHERE table_schema = current_schema() AND table_name = ? ORDER BY ordinal_position");
  auto index = db.Prepare(
      "SELECT count(*) FROM pg_catalog.pg_indexes WHERE schemaname = current_schema() "
      "AND indexname = ?");
  for (const auto& want : ExpectedSchema()) {
    if (want.type == "index") {
      index.Reset();
      index.Bind(1, want.name).Step();
      if (index.Int(0) == 0) check.Add("schema: index '" + want.name + "' is missing");
      continue;
    }
    std::vector<std::string> expected, found;
    auto info = reference.Prepare("SELECT name FROM pragma_table_info(?) ORDER BY cid");
    info.Bind(1, want.name);
    while (info.Step()) expected.push_back(info.Text(0));
    columns.Reset();
    columns.Bind(1, want.name);
    while (columns.Step()) found.push_back(columns.Text(0));
    if (found.empty()) {
      check.Add("schema: table '" + want.name + "' is missing");
    } else if (found != expected) {
      std::string list;
      for (const auto& c : found) list += (list.empty() ? "" : ", ") + c;
      check.Add("schema: table '" + want.name + "' has columns (" + list +
                "), not those of schema version " + std::to_string(kBankSchemaVersion));
    }
  }
}

void CheckClips(Checker& check) {
  check.Rows(
      "clip",
      "SELECT 'clip ' || id || ': first_frame ' || first_frame || ' > last_frame ' || last_frame "
      "FROM clips WHERE first_frame > last_frame");
  check.Rows("clip",
             "SELECT 'clip ' || id || ': complete but complete_seq is ' || "
             "coalesce(CAST(complete_seq AS TEXT), 'NULL') "
             "FROM clips WHERE (complete = 1) != (complete_seq IS NOT NULL)");
  check.Rows("sprite",
             "SELECT 'sprite ' || s.id || ': frame ' || s.frame || ' outside its clip ' || c.id || "
             "' [' || "
             "c.first_frame || ', ' || c.last_frame || ']' FROM sprites s JOIN clips c ON c.id = "
             "s.clip_id "
             "WHERE s.frame < c.first_frame OR s.frame > c.last_frame");
  check.Rows(
      "sprite",
      "SELECT 'sprite ' || s.id || ': camera ' || s.camera_id || ' / track ' || s.track_id || "
      "' differ from its clip ' || c.id || ' (camera ' || c.camera_id || ', track ' || c.track_id "
      "|| ')' "
      "FROM sprites s JOIN clips c ON c.id = s.clip_id "
      "WHERE s.camera_id != c.camera_id OR s.track_id != c.track_id");
  // A complete clip is a run of consecutive frames: one original per frame from first to last.
  check.Rows("clip",
             "SELECT 'clip ' || c.id || ': complete over frames [' || c.first_frame || ', ' || "
             "c.last_frame || "
             "'] but holds ' || count(s.id) || ' original sprites spanning [' || "
             "coalesce(CAST(min(s.frame) AS TEXT), '-') || "
             "', ' || coalesce(CAST(max(s.frame) AS TEXT), '-') || ']' "
             "FROM clips c LEFT JOIN sprites s ON s.clip_id = c.id AND s.mirrored = 0 WHERE "
             "c.complete = 1 "
             "GROUP BY c.id HAVING count(s.id) != c.last_frame - c.first_frame + 1 "
             "OR min(s.frame) != c.first_frame OR max(s.frame) != c.last_frame");
}

void CheckMirrors(Checker& check) {
  check.Rows("mirror",
             "SELECT 'sprite ' || id || ': mirrored = ' || mirrored || ' but mirror_of is ' || "
             "coalesce(CAST(mirror_of AS TEXT), 'NULL') FROM sprites WHERE (mirrored = 1) != "
             "(mirror_of IS NOT NULL)");
  check.Rows("mirror",
             "SELECT 'sprite ' || m.id || ': its original ' || o.id || ' is itself mirrored' "
             "FROM sprites m JOIN sprites o ON o.id = m.mirror_of WHERE o.mirrored != 0");
  check.Rows("mirror",
             "SELECT 'sprite ' || m.id || ': differs from its original ' || o.id || ' in clip, "
             "camera, track, frame "
             "or time' FROM sprites m JOIN sprites o ON o.id = m.mirror_of WHERE m.clip_id != "
             "o.clip_id OR "
             "m.camera_id != o.camera_id OR m.track_id != o.track_id OR m.frame != o.frame OR "
             "m.timestamp_ns != o.timestamp_ns");
  // Mirroring the billboard keeps where the subject stands, its speed, its size and colour.
  check.Rows(
      "mirror",
      "SELECT 'sprite ' || m.id || ': position, speed, billboard size, area, colour or "
      "eccentricity differ "
      "from its original ' || o.id FROM sprites m JOIN sprites o ON o.id = m.mirror_of WHERE "
      "abs(m.ground_x_m - o.ground_x_m) > 1e-6 OR abs(m.ground_y_m - o.ground_y_m) > 1e-6 OR "
      "abs(sqrt(m.velocity_x_m_s * m.velocity_x_m_s + m.velocity_y_m_s * m.velocity_y_m_s) - "
      "sqrt(o.velocity_x_m_s * o.velocity_x_m_s + o.velocity_y_m_s * o.velocity_y_m_s)) > "
      "1e-6 + 1e-4 * sqrt(o.velocity_x_m_s * o.velocity_x_m_s + o.velocity_y_m_s * "
      "o.velocity_y_m_s) OR "
      "m.billboard_w_px != o.billboard_w_px OR m.billboard_h_px != o.billboard_h_px OR "
      "m.px_per_m != o.px_per_m OR abs(m.area_px - o.area_px) > 1e-3 * (1 + abs(o.area_px)) OR "
      "abs(m.mean_r - o.mean_r) > 0.01 OR abs(m.mean_g - o.mean_g) > 0.01 OR "
      "abs(m.mean_b - o.mean_b) > 0.01 OR abs(m.eccentricity - o.eccentricity) > 1e-3");
  check.Rows("mirror",
             "SELECT 'sprite ' || p.sprite_id || ': a mirrored sprite stores pixels' "
             "FROM sprite_pixels p JOIN sprites s ON s.id = p.sprite_id WHERE s.mirrored = 1");
}

void CheckPixels(const sql::Db& db, Checker& check, BankVerifyReport& report) {
  check.Rows("pixels",
             "SELECT 'sprite ' || s.id || ': an original sprite without pixels' FROM sprites s "
             "LEFT JOIN sprite_pixels p ON p.sprite_id = s.id WHERE s.mirrored = 0 AND p.sprite_id "
             "IS NULL");
  check.Rows("pixels",
             "SELECT 'sprite ' || s.id || ': pixels are ' || p.width_px || 'x' || p.height_px || "
             "', billboard is ' || "
             "s.billboard_w_px || 'x' || s.billboard_h_px FROM sprites s JOIN sprite_pixels p ON "
             "p.sprite_id = s.id "
             "WHERE p.width_px != s.billboard_w_px OR p.height_px != s.billboard_h_px");
  PixelCodec codec;
  auto s = db.Prepare(
      "SELECT sprite_id, width_px, height_px, codec, data FROM sprite_pixels ORDER BY sprite_id");
  int64_t bad = 0;
  while (s.Step()) {
    ++report.pixel_blobs_checked;
    try {
      codec.Decode(s.Blob(4), s.Bytes(4), static_cast<int>(s.Int(1)), static_cast<int>(s.Int(2)),
                   s.Text(3));
    } catch (const WorkError& e) {
      if (bad++ < kMaxExamples)
        check.Add("pixels: sprite " + std::to_string(s.Int(0)) + ": " + e.what());
    }
  }
  if (bad > kMaxExamples)
    check.Add("pixels: " + std::to_string(bad - kMaxExamples) + " more blobs fail");
}

}  // namespace

BankVerifyReport VerifyBank(const std::string& path) {
  BankVerifyReport report;
  const bool postgres = sql::IsPostgresAddress(path);
  report.path = postgres ? sql::RedactAddress(path) : path;
  // Opening checks that the file is a bank of this schema version (InputError if not).
  if (!postgres && !std::filesystem::exists(path)) throw InputError(path, "no such sprite bank");
  sql::Db db = postgres ? sql::OpenPostgres(path, /*read_only=*/true)
                        : sql::OpenSqlite(path, SQLITE_OPEN_READONLY | SQLITE_OPEN_NOMUTEX);
  try {
    report.schema_version = PrepareBankSchema(db, /*writable=*/false);
  } catch (const sql::CorruptError& e) {
    // The header reads as a bank but the file is damaged beyond opening it.
    report.problems.push_back(std::string("open: ") + e.what());
    return report;
  } catch (const BusyError&) {
    throw;  // the server is not there: nothing was checked
  } catch (const WorkError& e) {
    report.problems.push_back(std::string("open: ") + e.what());
    return report;
  }
  Checker check(db, report);
  // One read transaction: every check sees the same snapshot while writers go on.
  check.Run("snapshot", [&] { db.impl().BeginRead(); });
  if (postgres) {
    // The server keeps its pages and foreign keys whole; what is ours to check is the schema.
    check.Run("schema", [&] { CheckPostgresSchema(db, check); });
  } else {
    check.Run("integrity", [&] {
      auto s = db.Prepare("PRAGMA integrity_check(100)");
      while (s.Step()) {
        if (s.Text(0) != "ok") check.Add("integrity: " + s.Text(0));
      }
    });
    check.Run("foreign keys", [&] {
      check.Rows(
          "foreign key",
          "SELECT \"table\" || ' row ' || coalesce(rowid, '?') || ' refers to a missing ' || "
          "parent FROM pragma_foreign_key_check");
    });
    check.Run("schema", [&] { CheckSchema(db, check); });
  }
  check.Run("clips", [&] {
    CheckClips(check);
    report.clips_checked = db.QueryInt("SELECT count(*) FROM clips");
    report.sprites_checked = db.QueryInt("SELECT count(*) FROM sprites");
  });
  check.Run("mirrors", [&] { CheckMirrors(check); });
  check.Run("pixels", [&] { CheckPixels(db, check, report); });
  db.impl().Rollback();
  return report;
}

std::vector<std::string> QuickCheckBank(const std::string& path) {
  std::vector<std::string> problems;
  std::error_code ec;
  // A PostgreSQL server keeps its own pages whole (and refuses a damaged one itself).
  if (sql::IsPostgresAddress(path) || !std::filesystem::exists(path, ec)) return problems;
  try {
    sql::Db db = sql::OpenSqlite(path, SQLITE_OPEN_READONLY | SQLITE_OPEN_NOMUTEX);
    auto s = db.Prepare("PRAGMA quick_check(20)");
    while (s.Step()) {
      std::string line = s.Text(0);
      std::replace(line.begin(), line.end(), '\n', ' ');
      if (line != "ok") problems.push_back(line);
    }
  } catch (const std::exception& e) {
    problems.push_back(e.what());
  }
  return problems;
}

void RefuseDamagedBank(const std::string& path) {
  const std::vector<std::string> damage = QuickCheckBank(path);
  if (damage.empty()) return;
  throw InputError(
      path, "the bank does not pass SQLite's quick check (" + damage.front() +
                (damage.size() > 1 ? ", and " + std::to_string(damage.size() - 1) + " more" : "") +
                "); nothing was written. Run `spritestation bank verify " + path +
                "` to see the damage");
}

}  // namespace ss
