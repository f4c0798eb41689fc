#pragma once
// The sprite bank's schema and its migrations (docs/formats.md).
// Rule: a shipped migration is never edited. A new schema version appends one
// migration that upgrades the previous version in place; a new bank is made by
// running every migration from version 0, so new and upgraded banks are identical.
#include <cstdint>
#include <string>
#include <vector>

namespace ss {

namespace sql {
class Db;
enum class Dialect;
}  // namespace sql

inline constexpr int kBankSchemaVersion = 3;
// PRAGMA application_id of every bank: "SSBK".
inline constexpr int32_t kBankApplicationId = 0x5353424B;

struct BankMigration {
  int version;          // the schema version this migration produces
  const char* summary;  // one line for the docs and the log
  const char* sql;      // run in the same transaction that sets the version
};

// Every migration of a dialect's schema, in order; the last one's version is
// kBankSchemaVersion. Both dialects have the same versions, tables, columns and constraints.
const std::vector<BankMigration>& BankMigrations(sql::Dialect dialect);

// Checks that `db` (opened on its file) is a sprite bank this build reads, sets the
// connection's pragmas, and, when `writable`, creates an empty file's schema or
// upgrades an older one. InputError naming the file and the version found vs expected.
// Returns the schema version. A SQLite bank keeps it in PRAGMA user_version (and its
// application_id), a PostgreSQL bank in meta's schema_version (and application).
int PrepareBankSchema(sql::Db& db, bool writable);

// Opens the bank at `path` (a SQLite file, or a `postgresql://` address: core/sql_postgres.h)
// and prepares it as PrepareBankSchema does. Read-only, a missing file or one that is not a
// regular file is an InputError naming it (SQLite would make an empty one).
sql::Db OpenBankDatabase(const std::string& path, bool writable);
// Why a SQLite bank cannot be at `path` (a folder, a device), or "" (a regular file, none yet, or
// a PostgreSQL address): the words OpenBankDatabase refuses it with, for `config check` to say.
std::string BankPathProblem(const std::string& path);
int ReadSchemaVersion(const sql::Db& db);

// Called inside the transaction that completes a clip, before it takes the next complete_seq:
// on PostgreSQL it holds a lock until that transaction ends, so that clips complete in the order
// of their complete_seq even with many writers (a reader asking for the clips completed after
// the last it saw misses none). SQLite's one writer needs nothing.
void SerializeClipCompletion(sql::Db& db);

// One object of sqlite_schema (SQLite banks): ("table"|"index", name, normalized CREATE text).
struct SchemaObject {
  std::string type;
  std::string name;
  std::string sql;
};
// The objects a bank of the current version must hold, from a fresh in-memory bank.
std::vector<SchemaObject> ExpectedSchema();
// The objects `db` holds (sqlite_* internals excluded).
std::vector<SchemaObject> ReadSchema(const sql::Db& db);

}  // namespace ss
