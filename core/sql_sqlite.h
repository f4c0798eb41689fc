#pragma once
// The SQLite driver of core/sql.h: a bank in one file (WAL mode), the embedded default.
// SQLite's result codes become the errors core/sql.h lists: SQLITE_NOTADB InputError,
// SQLITE_CORRUPT CorruptError, SQLITE_BUSY / SQLITE_LOCKED BusyError, the rest WorkError,
// each naming the file and SQLite's message.
#include <sqlite3.h>

#include <string>
#include <string_view>

#include "core/sql.h"

namespace ss::sql {

// Opens `path` with sqlite3_open_v2's `flags` (SQLITE_OPEN_*); throws naming `path` when it
// cannot. Extended result codes on.
Db OpenSqlite(const std::string& path, int flags);

// The sqlite3 handle of a connection OpenSqlite made (for pragmas and checks only SQLite has);
// WorkError for a connection of another driver.
sqlite3* SqliteHandle(const Db& db);

// Throws the exception that matches SQLite result code `rc` (see the file comment).
[[noreturn]] void Fail(sqlite3* db, int rc, const std::string& path, std::string_view what);

}  // namespace ss::sql
