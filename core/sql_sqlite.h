#pragma once
// Small move-only RAII wrappers over the sqlite3 C API, used by the sprite bank.
// Every failure throws: SQLITE_NOTADB -> InputError, SQLITE_CORRUPT -> CorruptError
// (an InputError: the file is damaged), SQLITE_BUSY / SQLITE_LOCKED -> BusyError
// (core/error_kinds.h: a WorkError worth retrying), anything else -> WorkError, each naming the
// database file and SQLite's message.
#include <sqlite3.h>

#include <cstdint>
#include <string>
#include <string_view>

#include "core/error.h"
#include "core/error_kinds.h"  // BusyError

namespace ss::sql {

// The database file is damaged (SQLITE_CORRUPT): bad input, which `bank verify` reports as damage.
class CorruptError : public InputError {
 public:
  using InputError::InputError;
};

// One prepared statement. Bind with 1-based indices, Step() until it returns false.
class Stmt {
 public:
  Stmt() = default;
  Stmt(sqlite3* db, std::string_view sql, const std::string& path);
  ~Stmt();
  Stmt(Stmt&& other) noexcept;
  Stmt& operator=(Stmt&& other) noexcept;
  Stmt(const Stmt&) = delete;
  Stmt& operator=(const Stmt&) = delete;

  Stmt& Bind(int index, int64_t value);
  Stmt& Bind(int index, double value);
  Stmt& Bind(int index, std::string_view text);
  Stmt& BindBlob(int index, const void* data, size_t size);
  Stmt& BindNull(int index);
  // True when a row is ready; false when done. Throws on error.
  bool Step();
  // Resets for the next execution and clears the bindings.
  void Reset();

  int64_t Int(int col) const { return sqlite3_column_int64(stmt_, col); }
  double Real(int col) const { return sqlite3_column_double(stmt_, col); }
  bool IsNull(int col) const { return sqlite3_column_type(stmt_, col) == SQLITE_NULL; }
  std::string Text(int col) const;
  const void* Blob(int col) const { return sqlite3_column_blob(stmt_, col); }
  size_t Bytes(int col) const { return static_cast<size_t>(sqlite3_column_bytes(stmt_, col)); }

 private:
  sqlite3_stmt* stmt_ = nullptr;
  sqlite3* db_ = nullptr;
  std::string path_;
};

// One database connection.
class Db {
 public:
  Db() = default;
  // sqlite3_open_v2 with `flags`; throws naming `path` when it cannot open.
  Db(const std::string& path, int flags);
  ~Db();
  Db(Db&& other) noexcept;
  Db& operator=(Db&& other) noexcept;
  Db(const Db&) = delete;
  Db& operator=(const Db&) = delete;

  sqlite3* get() const { return db_; }
  const std::string& path() const { return path_; }
  // Runs one or more statements that return no rows.
  void Exec(const std::string& sql);
  Stmt Prepare(std::string_view sql) const { return Stmt(db_, sql, path_); }
  // The single integer a query such as "PRAGMA user_version" returns (0 when no row).
  int64_t QueryInt(std::string_view sql) const;

 private:
  sqlite3* db_ = nullptr;
  std::string path_;
};

// Throws the exception that matches SQLite result code `rc` (see the file comment).
[[noreturn]] void Fail(sqlite3* db, int rc, const std::string& path, std::string_view what);

// BEGIN IMMEDIATE on construction; ROLLBACK on destruction unless Commit() was called.
class Transaction {
 public:
  explicit Transaction(Db& db);
  ~Transaction();
  Transaction(const Transaction&) = delete;
  Transaction& operator=(const Transaction&) = delete;
  void Commit();

 private:
  Db& db_;
  bool done_ = false;
};

}  // namespace ss::sql
