#include "core/bank_schema.h"

#include <sqlite3.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <system_error>

#include "core/error.h"
#include "core/log.h"
#include "core/sql_postgres.h"
#include "core/sql_sqlite.h"

namespace ss {
namespace {

// Version 1: the first schema. Column meanings: docs/formats.md.
constexpr const char* kSchemaV1 = R"sql(
CREATE TABLE meta (
  key   TEXT PRIMARY KEY NOT NULL,
  value TEXT NOT NULL
) WITHOUT ROWID;

CREATE TABLE sessions (
  id      INTEGER PRIMARY KEY,
  uid     TEXT NOT NULL UNIQUE CHECK (length(uid) > 0),
  name    TEXT NOT NULL DEFAULT '',
  created TEXT NOT NULL DEFAULT '',
  source  TEXT NOT NULL DEFAULT ''
);

CREATE TABLE cameras (
  id          INTEGER PRIMARY KEY,
  session_id  INTEGER NOT NULL REFERENCES sessions(id) ON DELETE CASCADE,
  name        TEXT NOT NULL CHECK (length(name) > 0),
  cameramodel TEXT NOT NULL DEFAULT '',
  width       INTEGER NOT NULL CHECK (width >= 0),
  height      INTEGER NOT NULL CHECK (height >= 0),
  UNIQUE (session_id, name)
);

CREATE TABLE clips (
  id           INTEGER PRIMARY KEY,
  camera_id    INTEGER NOT NULL REFERENCES cameras(id) ON DELETE CASCADE,
  track_id     INTEGER NOT NULL,
  first_frame  INTEGER NOT NULL,
  last_frame   INTEGER NOT NULL,
  complete     INTEGER NOT NULL DEFAULT 0 CHECK (complete IN (0, 1)),
  complete_seq INTEGER UNIQUE,
  UNIQUE (camera_id, track_id, first_frame),
  CHECK (first_frame <= last_frame),
  CHECK ((complete = 1) = (complete_seq IS NOT NULL))
);

CREATE TABLE sprites (
  id             INTEGER PRIMARY KEY,
  clip_id        INTEGER NOT NULL REFERENCES clips(id) ON DELETE CASCADE,
  camera_id      INTEGER NOT NULL REFERENCES cameras(id) ON DELETE CASCADE,
  track_id       INTEGER NOT NULL,
  frame          INTEGER NOT NULL,
  timestamp_ns   INTEGER NOT NULL,
  mirrored       INTEGER NOT NULL CHECK (mirrored IN (0, 1)),
  mirror_of      INTEGER REFERENCES sprites(id) ON DELETE CASCADE,
  ground_x_m     REAL NOT NULL,
  ground_y_m     REAL NOT NULL,
  velocity_x_m_s REAL NOT NULL,
  velocity_y_m_s REAL NOT NULL,
  mean_r         REAL NOT NULL,
  mean_g         REAL NOT NULL,
  mean_b         REAL NOT NULL,
  area_px        REAL NOT NULL,
  eccentricity   REAL NOT NULL,
  bbox_x         INTEGER NOT NULL,
  bbox_y         INTEGER NOT NULL,
  bbox_w         INTEGER NOT NULL,
  bbox_h         INTEGER NOT NULL,
  billboard_w_px INTEGER NOT NULL CHECK (billboard_w_px > 0),
  billboard_h_px INTEGER NOT NULL CHECK (billboard_h_px > 0),
  px_per_m       REAL NOT NULL CHECK (px_per_m > 0),
  anchor_x_px    REAL NOT NULL,
  anchor_y_px    REAL NOT NULL,
  UNIQUE (camera_id, frame, track_id, mirrored),
  CHECK ((mirrored = 1) = (mirror_of IS NOT NULL))
);
CREATE INDEX sprites_by_clip ON sprites (clip_id, mirrored, frame);
CREATE UNIQUE INDEX sprites_by_mirror_of ON sprites (mirror_of) WHERE mirror_of IS NOT NULL;

CREATE TABLE sprite_tags (
  sprite_id INTEGER NOT NULL REFERENCES sprites(id) ON DELETE CASCADE,
  tag       TEXT NOT NULL CHECK (length(tag) > 0),
  PRIMARY KEY (sprite_id, tag)
) WITHOUT ROWID;
CREATE INDEX sprite_tags_by_tag ON sprite_tags (tag, sprite_id);

CREATE TABLE sprite_pixels (
  sprite_id INTEGER PRIMARY KEY REFERENCES sprites(id) ON DELETE CASCADE,
  width_px  INTEGER NOT NULL CHECK (width_px > 0),
  height_px INTEGER NOT NULL CHECK (height_px > 0),
  codec     TEXT NOT NULL,
  data      BLOB NOT NULL
);

CREATE TABLE transitions (
  from_sprite INTEGER NOT NULL REFERENCES sprites(id) ON DELETE CASCADE,
  to_sprite   INTEGER NOT NULL REFERENCES sprites(id) ON DELETE CASCADE,
  d           REAL NOT NULL,
  cost        REAL NOT NULL,
  PRIMARY KEY (from_sprite, to_sprite)
) WITHOUT ROWID;
CREATE INDEX transitions_by_to ON transitions (to_sprite);

INSERT INTO meta (key, value) VALUES ('application', 'spritestation sprite bank');
)sql";

// Version 2: a person's judgements of sprite pairs (the console's labelling page), kept
// in the bank beside the sprites they name; exported as the labels CSV that
// `transitions train` reads.
constexpr const char* kSchemaV2 = R"sql(
CREATE TABLE transition_labels (
  from_sprite INTEGER NOT NULL REFERENCES sprites(id) ON DELETE CASCADE,
  to_sprite   INTEGER NOT NULL REFERENCES sprites(id) ON DELETE CASCADE,
  label       TEXT NOT NULL CHECK (label IN ('yes', 'no', 'skip')),
  labelled_at TEXT NOT NULL,
  source      TEXT NOT NULL DEFAULT '',
  PRIMARY KEY (from_sprite, to_sprite),
  CHECK (from_sprite <> to_sprite)
) WITHOUT ROWID;
CREATE INDEX transition_labels_by_to ON transition_labels (to_sprite);
)sql";

// Version 3: floor sprites (issue 38): what kind each sprite is, and a floor sprite's heading.
// Every sprite stored before is upright.
constexpr const char* kSchemaV3 = R"sql(
ALTER TABLE sprites ADD COLUMN kind TEXT NOT NULL DEFAULT 'upright'
  CHECK (kind IN ('upright', 'floor'));
ALTER TABLE sprites ADD COLUMN heading_rad REAL NOT NULL DEFAULT 0;
)sql";

// The same schema in PostgreSQL's types (a bank shared by many stations: docs/scaling.md).
// Ids come from identity sequences, so writers on any hosts never clash; every number keeps
// SQLite's range (BIGINT, DOUBLE PRECISION); text compares byte by byte (COLLATE "C") as in
// SQLite, so that both order the same rows the same way. Flags stay 0/1 integers, so that the
// bank's queries are the same text for both.
constexpr const char* kPostgresSchemaV1 = R"sql(
CREATE TABLE meta (
  key   TEXT COLLATE "C" PRIMARY KEY NOT NULL,
  value TEXT COLLATE "C" NOT NULL
);

CREATE TABLE sessions (
  id      BIGINT GENERATED BY DEFAULT AS IDENTITY PRIMARY KEY,
  uid     TEXT COLLATE "C" NOT NULL UNIQUE CHECK (length(uid) > 0),
  name    TEXT COLLATE "C" NOT NULL DEFAULT '',
  created TEXT COLLATE "C" NOT NULL DEFAULT '',
  source  TEXT COLLATE "C" NOT NULL DEFAULT ''
);

CREATE TABLE cameras (
  id          BIGINT GENERATED BY DEFAULT AS IDENTITY PRIMARY KEY,
  session_id  BIGINT NOT NULL REFERENCES sessions(id) ON DELETE CASCADE,
  name        TEXT COLLATE "C" NOT NULL CHECK (length(name) > 0),
  cameramodel TEXT COLLATE "C" NOT NULL DEFAULT '',
  width       INTEGER NOT NULL CHECK (width >= 0),
  height      INTEGER NOT NULL CHECK (height >= 0),
  UNIQUE (session_id, name)
);

CREATE TABLE clips (
  id           BIGINT GENERATED BY DEFAULT AS IDENTITY PRIMARY KEY,
  camera_id    BIGINT NOT NULL REFERENCES cameras(id) ON DELETE CASCADE,
  track_id     BIGINT NOT NULL,
  first_frame  BIGINT NOT NULL,
  last_frame   BIGINT NOT NULL,
  complete     SMALLINT NOT NULL DEFAULT 0 CHECK (complete IN (0, 1)),
  complete_seq BIGINT UNIQUE,
  UNIQUE (camera_id, track_id, first_frame),
  CHECK (first_frame <= last_frame),
  CHECK ((complete = 1) = (complete_seq IS NOT NULL))
);

CREATE TABLE sprites (
  id             BIGINT GENERATED BY DEFAULT AS IDENTITY PRIMARY KEY,
  clip_id        BIGINT NOT NULL REFERENCES clips(id) ON DELETE CASCADE,
  camera_id      BIGINT NOT NULL REFERENCES cameras(id) ON DELETE CASCADE,
  track_id       BIGINT NOT NULL,
  frame          BIGINT NOT NULL,
  timestamp_ns   BIGINT NOT NULL,
  mirrored       SMALLINT NOT NULL CHECK (mirrored IN (0, 1)),
  mirror_of      BIGINT REFERENCES sprites(id) ON DELETE CASCADE,
  ground_x_m     DOUBLE PRECISION NOT NULL,
  ground_y_m     DOUBLE PRECISION NOT NULL,
  velocity_x_m_s DOUBLE PRECISION NOT NULL,
  velocity_y_m_s DOUBLE PRECISION NOT NULL,
  mean_r         DOUBLE PRECISION NOT NULL,
  mean_g         DOUBLE PRECISION NOT NULL,
  mean_b         DOUBLE PRECISION NOT NULL,
  area_px        DOUBLE PRECISION NOT NULL,
  eccentricity   DOUBLE PRECISION NOT NULL,
  bbox_x         INTEGER NOT NULL,
  bbox_y         INTEGER NOT NULL,
  bbox_w         INTEGER NOT NULL,
  bbox_h         INTEGER NOT NULL,
  billboard_w_px INTEGER NOT NULL CHECK (billboard_w_px > 0),
  billboard_h_px INTEGER NOT NULL CHECK (billboard_h_px > 0),
  px_per_m       DOUBLE PRECISION NOT NULL CHECK (px_per_m > 0),
  anchor_x_px    DOUBLE PRECISION NOT NULL,
  anchor_y_px    DOUBLE PRECISION NOT NULL,
  UNIQUE (camera_id, frame, track_id, mirrored),
  CHECK ((mirrored = 1) = (mirror_of IS NOT NULL))
);
CREATE INDEX sprites_by_clip ON sprites (clip_id, mirrored, frame);
CREATE UNIQUE INDEX sprites_by_mirror_of ON sprites (mirror_of) WHERE mirror_of IS NOT NULL;

CREATE TABLE sprite_tags (
  sprite_id BIGINT NOT NULL REFERENCES sprites(id) ON DELETE CASCADE,
  tag       TEXT COLLATE "C" NOT NULL CHECK (length(tag) > 0),
  PRIMARY KEY (sprite_id, tag)
);
CREATE INDEX sprite_tags_by_tag ON sprite_tags (tag, sprite_id);

CREATE TABLE sprite_pixels (
  sprite_id BIGINT PRIMARY KEY REFERENCES sprites(id) ON DELETE CASCADE,
  width_px  INTEGER NOT NULL CHECK (width_px > 0),
  height_px INTEGER NOT NULL CHECK (height_px > 0),
  codec     TEXT COLLATE "C" NOT NULL,
  data      BYTEA NOT NULL
);
ALTER TABLE sprite_pixels ALTER COLUMN data SET STORAGE EXTERNAL;

CREATE TABLE transitions (
  from_sprite BIGINT NOT NULL REFERENCES sprites(id) ON DELETE CASCADE,
  to_sprite   BIGINT NOT NULL REFERENCES sprites(id) ON DELETE CASCADE,
  d           DOUBLE PRECISION NOT NULL,
  cost        DOUBLE PRECISION NOT NULL,
  PRIMARY KEY (from_sprite, to_sprite)
);
CREATE INDEX transitions_by_to ON transitions (to_sprite);

INSERT INTO meta (key, value) VALUES ('application', 'spritestation sprite bank');
)sql";

constexpr const char* kPostgresSchemaV2 = R"sql(
CREATE TABLE transition_labels (
  from_sprite BIGINT NOT NULL REFERENCES sprites(id) ON DELETE CASCADE,
  to_sprite   BIGINT NOT NULL REFERENCES sprites(id) ON DELETE CASCADE,
  label       TEXT COLLATE "C" NOT NULL CHECK (label IN ('yes', 'no', 'skip')),
  labelled_at TEXT COLLATE "C" NOT NULL,
  source      TEXT COLLATE "C" NOT NULL DEFAULT '',
  PRIMARY KEY (from_sprite, to_sprite),
  CHECK (from_sprite <> to_sprite)
);
CREATE INDEX transition_labels_by_to ON transition_labels (to_sprite);
)sql";

constexpr const char* kPostgresSchemaV3 = R"sql(
ALTER TABLE sprites ADD COLUMN kind TEXT COLLATE "C" NOT NULL DEFAULT 'upright'
  CHECK (kind IN ('upright', 'floor'));
ALTER TABLE sprites ADD COLUMN heading_rad DOUBLE PRECISION NOT NULL DEFAULT 0;
)sql";

std::string Hex(int64_t v) {
  char buffer[32];
  std::snprintf(buffer, sizeof(buffer), "0x%08llx",
                static_cast<unsigned long long>(v) & 0xffffffffULL);
  return buffer;
}

// Runs every migration above `from` in one transaction (re-reading the version
// inside it, so two writers creating the same bank do not both migrate).
void MigrateSqlite(sql::Db& db) {
  sql::Transaction tx(db);
  const int from = static_cast<int>(db.QueryInt("PRAGMA user_version"));
  for (const auto& m : BankMigrations(sql::Dialect::kSqlite)) {
    if (m.version <= from) continue;
    // A new bank (from 0) is routine; an upgrade of an existing one is worth telling.
    Log("core.bank")
        ->log(from == 0 ? spdlog::level::debug : spdlog::level::info,
              "{}: schema version {} -> {} ({})", db.path(), m.version - 1, m.version, m.summary);
    db.Exec(m.sql);
    db.Exec("PRAGMA application_id = " + std::to_string(kBankApplicationId));
    db.Exec("PRAGMA user_version = " + std::to_string(m.version));
    auto set = db.Prepare("INSERT OR REPLACE INTO meta (key, value) VALUES ('schema_version', ?)");
    set.Bind(1, std::to_string(m.version));
    set.Step();
  }
  tx.Commit();
}

constexpr const char* kApplication = "spritestation sprite bank";

// Refuses what is not a bank this build reads (the same verdicts for both dialects).
void CheckVersion(const std::string& path, bool empty, bool is_bank, const std::string& what_it_is,
                  int64_t version, bool writable) {
  const std::string expected = "expected " + std::to_string(kBankSchemaVersion);
  if (empty) {
    if (!writable) throw InputError(path, "not a sprite bank (an empty database)");
  } else if (!is_bank) {
    throw InputError(path, "not a sprite bank (" + what_it_is + ")");
  } else if (version > kBankSchemaVersion) {
    throw InputError(path, "sprite bank schema version " + std::to_string(version) +
                               " is newer than this build reads (" + expected + ")");
  } else if (version < 1) {
    throw InputError(path, "sprite bank schema version " + std::to_string(version) +
                               " is unknown (" + expected + ")");
  } else if (version < kBankSchemaVersion && !writable) {
    throw InputError(
        path, "sprite bank schema version " + std::to_string(version) + " is older (" + expected +
                  "); open it with a writer (spritestation bank upgrade) to upgrade it in place");
  }
}

int PrepareSqlite(sql::Db& db, bool writable) {
  const std::string& path = db.path();
  sqlite3_busy_timeout(sql::SqliteHandle(db), 10000);
  // The first read of the file: a file that is not SQLite fails here with InputError.
  const int64_t app_id = db.QueryInt("PRAGMA application_id");
  int64_t version = db.QueryInt("PRAGMA user_version");
  const int64_t objects = db.QueryInt("SELECT count(*) FROM sqlite_schema");
  CheckVersion(path, app_id == 0 && version == 0 && objects == 0, app_id == kBankApplicationId,
               "application_id " + Hex(app_id) + ", expected " + Hex(kBankApplicationId), version,
               writable);

  db.Exec("PRAGMA foreign_keys = ON");
  if (writable) {
    sql::Stmt mode = db.Prepare("PRAGMA journal_mode = WAL");
    if (!mode.Step() || mode.Text(0) != "wal") {
      throw WorkError(path,
                      "cannot switch the bank to WAL mode (journal_mode " + mode.Text(0) + ")");
    }
    mode.Reset();
    db.Exec("PRAGMA synchronous = NORMAL");
    if (version < kBankSchemaVersion) {
      MigrateSqlite(db);
      version = db.QueryInt("PRAGMA user_version");
    }
  }
  return static_cast<int>(version);
}

// A PostgreSQL bank is the tables of one schema (the connection's current_schema(), `public`
// unless the address sets search_path); meta holds its application and schema version.
struct PostgresState {
  bool empty = true;
  bool is_bank = false;
  std::string what_it_is;
  int64_t version = 0;
};

PostgresState ReadPostgresState(sql::Db& db) {
  PostgresState state;
  const int64_t tables =
      db.QueryInt("SELECT count(*) FROM pg_catalog.pg_tables WHERE schemaname = current_schema()");
  const bool has_meta =
      db.QueryInt(
          "SELECT count(*) FROM pg_catalog.pg_tables WHERE schemaname = current_schema() "
          "AND tablename = 'meta'") > 0;
  state.empty = tables == 0;
  state.what_it_is =
      std::to_string(tables) + " tables in its schema, none of them a bank's meta table";
  if (!has_meta) return state;
  auto meta =
      db.Prepare("SELECT key, value FROM meta WHERE key IN ('application', 'schema_version')");
  std::string application, version = "0";
  while (meta.Step()) (meta.Text(0) == "application" ? application : version) = meta.Text(1);
  state.is_bank = application == kApplication;
  state.what_it_is = "meta.application is '" + application + "', expected '" + kApplication + "'";
  state.version = std::atoll(version.c_str());
  return state;
}

int PreparePostgres(sql::Db& db, bool writable) {
  PostgresState state = ReadPostgresState(db);
  CheckVersion(db.path(), state.empty, state.is_bank, state.what_it_is, state.version, writable);
  if (!writable || state.version >= kBankSchemaVersion) return static_cast<int>(state.version);
  // Migrate under a lock, re-reading the version inside it: two writers creating the same bank
  // at once (three daemons starting together) migrate it once.
  sql::Transaction tx(db);
  db.Exec("SELECT pg_advisory_xact_lock(" + std::to_string(kBankApplicationId) + ", 1)");
  state = ReadPostgresState(db);
  CheckVersion(db.path(), state.empty, state.is_bank, state.what_it_is, state.version, writable);
  for (const auto& m : BankMigrations(sql::Dialect::kPostgres)) {
    if (m.version <= state.version) continue;
    Log("core.bank")
        ->log(state.version == 0 ? spdlog::level::debug : spdlog::level::info,
              "{}: schema version {} -> {} ({})", db.path(), m.version - 1, m.version, m.summary);
    db.Exec(m.sql);
    auto set = db.Prepare(
        "INSERT INTO meta (key, value) VALUES ('schema_version', ?) "
        "ON CONFLICT (key) DO UPDATE SET value = excluded.value");
    set.Bind(1, std::to_string(m.version)).Step();
  }
  tx.Commit();
  return kBankSchemaVersion;
}

std::string Normalize(const std::string& sql) {
  std::string out;
  bool space = false;
  for (char c : sql) {
    if (c == ' ' || c == '\n' || c == '\t' || c == '\r') {
      space = true;
      continue;
    }
    if (space && !out.empty()) out += ' ';
    space = false;
    out += c;
  }
  return out;
}

}  // namespace

const std::vector<BankMigration>& BankMigrations(sql::Dialect dialect) {
  static const std::vector<BankMigration> sqlite = {
      {1, "initial schema: sessions, cameras, clips, sprites, tags, pixels, transitions",
       kSchemaV1},
      {2, "transition_labels: a person's yes / no / skip on sprite pairs", kSchemaV2},
      {3, "sprites.kind and heading_rad: floor sprites, seen from above", kSchemaV3},
  };
  static const std::vector<BankMigration> postgres = {
      {1, sqlite[0].summary, kPostgresSchemaV1},
      {2, sqlite[1].summary, kPostgresSchemaV2},
      {3, sqlite[2].summary, kPostgresSchemaV3},
  };
  return dialect == sql::Dialect::kPostgres ? postgres : sqlite;
}

int PrepareBankSchema(sql::Db& db, bool writable) {
  return db.dialect() == sql::Dialect::kPostgres ? PreparePostgres(db, writable)
                                                 : PrepareSqlite(db, writable);
}

std::string BankPathProblem(const std::string& path) {
  if (sql::IsPostgresAddress(path)) return "";
  std::error_code ec;
  const auto status = std::filesystem::status(path, ec);
  if (!std::filesystem::exists(status)) return "";  // a new bank: SQLite makes it
  if (std::filesystem::is_directory(status)) return "not a sprite bank (a folder)";
  if (!std::filesystem::is_regular_file(status)) return "not a sprite bank (not a regular file)";
  return "";
}

sql::Db OpenBankDatabase(const std::string& path, bool writable) {
  if (sql::IsPostgresAddress(path)) {
    sql::Db db = sql::OpenPostgres(path, !writable);
    PrepareBankSchema(db, writable);
    return db;
  }
  std::error_code ec;
  if (!writable && !std::filesystem::exists(path, ec))
    throw InputError(path, "no such sprite bank");
  if (const std::string problem = BankPathProblem(path); !problem.empty())
    throw InputError(path, problem);
  const int flags = (writable ? SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE : SQLITE_OPEN_READONLY) |
                    SQLITE_OPEN_NOMUTEX;
  sql::Db db = sql::OpenSqlite(path, flags);
  PrepareBankSchema(db, writable);
  return db;
}

int ReadSchemaVersion(const sql::Db& db) {
  if (db.dialect() == sql::Dialect::kSqlite)
    return static_cast<int>(db.QueryInt("PRAGMA user_version"));
  auto meta = db.Prepare("SELECT value FROM meta WHERE key = 'schema_version'");
  return meta.Step() ? std::atoi(meta.Text(0).c_str()) : 0;
}

void SerializeClipCompletion(sql::Db& db) {
  if (db.dialect() == sql::Dialect::kPostgres) {
    db.Exec("SELECT pg_advisory_xact_lock(" + std::to_string(kBankApplicationId) + ", 2)");
  }
}

std::vector<SchemaObject> ReadSchema(const sql::Db& db) {
  std::vector<SchemaObject> objects;
  sql::Stmt stmt = db.Prepare(
      "SELECT type, name, sql FROM sqlite_schema WHERE name NOT LIKE 'sqlite_%' AND sql IS NOT "
      "NULL "
      "ORDER BY type, name");
  while (stmt.Step()) objects.push_back({stmt.Text(0), stmt.Text(1), Normalize(stmt.Text(2))});
  return objects;
}

std::vector<SchemaObject> ExpectedSchema() {
  sql::Db db =
      sql::OpenSqlite(":memory:", SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE | SQLITE_OPEN_MEMORY);
  for (const auto& m : BankMigrations(sql::Dialect::kSqlite)) db.Exec(m.sql);
  return ReadSchema(db);
}

}  // namespace ss
