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
}

inline constexpr int kBankSchemaVersion = 2;
// PRAGMA application_id of every bank: "SSBK".
inline constexpr int32_t kBankApplicationId = 0x5353424B;

struct BankMigration {
  int version;          // the schema version this migration produces
  const char* summary;  // one line for the docs and the log
  const char* sql;      // run in the same transaction that sets the version
};

// Every migration, in order; the last one's version is kBankSchemaVersion.
const std::vector<BankMigration>& BankMigrations();

// Checks that `db` (opened on its file) is a sprite bank this build reads, sets the
// connection's pragmas, and, when `writable`, creates an empty file's schema or
// upgrades an older one. InputError naming the file and the version found vs expected.
// Returns the schema version.
int PrepareBankSchema(sql::Db& db, bool writable);

// One object of sqlite_schema: ("table"|"index", name, normalized CREATE text).
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
