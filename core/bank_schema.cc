#include "core/bank_schema.h"

#include <sqlite3.h>

#include <cstdio>

#include "core/bank_sqlite.h"
#include "core/error.h"
#include "core/log.h"

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

std::string Hex(int64_t v) {
  char buffer[32];
  std::snprintf(buffer, sizeof(buffer), "0x%08llx", static_cast<unsigned long long>(v) & 0xffffffffULL);
  return buffer;
}

// Runs every migration above `from` in one transaction (re-reading the version
// inside it, so two writers creating the same bank do not both migrate).
void Migrate(sql::Db& db) {
  sql::Transaction tx(db);
  const int from = static_cast<int>(db.QueryInt("PRAGMA user_version"));
  for (const auto& m : BankMigrations()) {
    if (m.version <= from) continue;
    // A new bank (from 0) is routine; an upgrade of an existing one is worth telling.
    Log("core.bank")->log(from == 0 ? spdlog::level::debug : spdlog::level::info, "{}: schema version {} -> {} ({})",
                          db.path(), m.version - 1, m.version, m.summary);
    db.Exec(m.sql);
    db.Exec("PRAGMA application_id = " + std::to_string(kBankApplicationId));
    db.Exec("PRAGMA user_version = " + std::to_string(m.version));
    auto set = db.Prepare("INSERT OR REPLACE INTO meta (key, value) VALUES ('schema_version', ?)");
    set.Bind(1, std::to_string(m.version));
    set.Step();
  }
  tx.Commit();
}

std::string Normalize(std::string sql) {
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

const std::vector<BankMigration>& BankMigrations() {
  static const std::vector<BankMigration> migrations = {
      {1, "initial schema: sessions, cameras, clips, sprites, tags, pixels, transitions", kSchemaV1},
      {2, "transition_labels: a person's yes / no / skip on sprite pairs", kSchemaV2},
  };
  return migrations;
}

int PrepareBankSchema(sql::Db& db, bool writable) {
  const std::string& path = db.path();
  sqlite3_busy_timeout(db.get(), 10000);
  // The first read of the file: a file that is not SQLite fails here with InputError.
  const int64_t app_id = db.QueryInt("PRAGMA application_id");
  int64_t version = db.QueryInt("PRAGMA user_version");
  const int64_t objects = db.QueryInt("SELECT count(*) FROM sqlite_schema");
  const std::string expected = "expected " + std::to_string(kBankSchemaVersion);

  if (app_id == 0 && version == 0 && objects == 0) {
    if (!writable) throw InputError(path, "not a sprite bank (an empty database)");
  } else if (app_id != kBankApplicationId) {
    throw InputError(path, "not a sprite bank (application_id " + Hex(app_id) + ", expected " +
                               Hex(kBankApplicationId) + ")");
  } else if (version > kBankSchemaVersion) {
    throw InputError(path, "sprite bank schema version " + std::to_string(version) +
                               " is newer than this build reads (" + expected + ")");
  } else if (version < 1) {
    throw InputError(path, "sprite bank schema version " + std::to_string(version) + " is unknown (" +
                               expected + ")");
  } else if (version < kBankSchemaVersion && !writable) {
    throw InputError(path, "sprite bank schema version " + std::to_string(version) + " is older (" + expected +
                               "); open it with a writer (spritestation bank upgrade) to upgrade it in place");
  }

  db.Exec("PRAGMA foreign_keys = ON");
  if (writable) {
    sql::Stmt mode = db.Prepare("PRAGMA journal_mode = WAL");
    if (!mode.Step() || mode.Text(0) != "wal") {
      throw WorkError(path, "cannot switch the bank to WAL mode (journal_mode " + mode.Text(0) + ")");
    }
    mode.Reset();
    db.Exec("PRAGMA synchronous = NORMAL");
    if (version < kBankSchemaVersion) {
      Migrate(db);
      version = db.QueryInt("PRAGMA user_version");
    }
  }
  return static_cast<int>(version);
}

std::vector<SchemaObject> ReadSchema(const sql::Db& db) {
  std::vector<SchemaObject> objects;
  sql::Stmt stmt = db.Prepare(
      "SELECT type, name, sql FROM sqlite_schema WHERE name NOT LIKE 'sqlite_%' AND sql IS NOT NULL "
      "ORDER BY type, name");
  while (stmt.Step()) objects.push_back({stmt.Text(0), stmt.Text(1), Normalize(stmt.Text(2))});
  return objects;
}

std::vector<SchemaObject> ExpectedSchema() {
  sql::Db db(":memory:", SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE | SQLITE_OPEN_MEMORY);
  for (const auto& m : BankMigrations()) db.Exec(m.sql);
  return ReadSchema(db);
}

}  // namespace ss
