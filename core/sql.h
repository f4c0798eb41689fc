#pragma once
// The SQL database a sprite bank lives in, behind one small interface with two drivers:
// SQLite (core/sql_sqlite.h: a file, the embedded default) and PostgreSQL (core/sql_postgres.h:
// a server shared by many stations). The bank's SQL is written once, in the dialect both
// accept: `?` placeholders, `INSERT ... ON CONFLICT ... DO NOTHING / DO UPDATE`, `RETURNING id`;
// what differs (the schema's column types, transactions' locking, the schema version's home)
// asks `dialect()`.
//
// Every failure throws, naming the database (a PostgreSQL address without its password):
// a damaged database CorruptError (an InputError), one that is not a database InputError, a
// lock held past the wait or a lost connection BusyError (core/error_kinds.h: worth retrying),
// anything else WorkError.
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <string_view>

#include "core/error.h"
#include "core/error_kinds.h"  // BusyError

namespace ss::sql {

enum class Dialect { kSqlite, kPostgres };

// The database is damaged: bad input, which `bank verify` reports as damage.
class CorruptError : public InputError {
 public:
  using InputError::InputError;
};

// What a driver implements for one prepared statement (see Stmt).
class StmtImpl {
 public:
  virtual ~StmtImpl() = default;
  virtual void Bind(int index, int64_t value) = 0;
  virtual void Bind(int index, double value) = 0;
  virtual void Bind(int index, std::string_view text) = 0;
  virtual void BindBlob(int index, const void* data, size_t size) = 0;
  virtual void BindNull(int index) = 0;
  virtual bool Step() = 0;
  virtual void Reset() = 0;
  virtual int64_t Int(int col) const = 0;
  virtual double Real(int col) const = 0;
  virtual bool IsNull(int col) const = 0;
  virtual std::string Text(int col) const = 0;
  virtual const void* Blob(int col) const = 0;
  virtual size_t Bytes(int col) const = 0;
  virtual int64_t Changes() const = 0;
};

// One prepared statement. Bind with 1-based indices, Step() until it returns false; Reset()
// before the next execution (it clears the bindings). Columns are read from the current row.
class Stmt {
 public:
  Stmt() = default;
  explicit Stmt(std::unique_ptr<StmtImpl> impl) : impl_(std::move(impl)) {}

  Stmt& Bind(int index, int64_t value) { return impl_->Bind(index, value), *this; }
  Stmt& Bind(int index, double value) { return impl_->Bind(index, value), *this; }
  Stmt& Bind(int index, std::string_view text) { return impl_->Bind(index, text), *this; }
  Stmt& BindBlob(int index, const void* data, size_t size) {
    return impl_->BindBlob(index, data, size), *this;
  }
  Stmt& BindNull(int index) { return impl_->BindNull(index), *this; }
  // True when a row is ready; false when done. Throws on error.
  bool Step() { return impl_->Step(); }
  void Reset() { impl_->Reset(); }

  int64_t Int(int col) const { return impl_->Int(col); }
  double Real(int col) const { return impl_->Real(col); }
  bool IsNull(int col) const { return impl_->IsNull(col); }
  std::string Text(int col) const { return impl_->Text(col); }
  const void* Blob(int col) const { return impl_->Blob(col); }
  size_t Bytes(int col) const { return impl_->Bytes(col); }
  // Rows the last execution inserted, updated or deleted.
  int64_t Changes() const { return impl_->Changes(); }

 private:
  std::unique_ptr<StmtImpl> impl_;
};

// What a driver implements for one connection (see Db).
class DbImpl {
 public:
  virtual ~DbImpl() = default;
  virtual Dialect dialect() const = 0;
  virtual const std::string& path() const = 0;
  virtual void Exec(const std::string& sql) = 0;
  virtual std::unique_ptr<StmtImpl> Prepare(std::string_view sql) = 0;
  // A write transaction: SQLite takes the write lock at once (BEGIN IMMEDIATE).
  virtual void BeginWrite() = 0;
  // A read transaction that sees one snapshot until it ends.
  virtual void BeginRead() = 0;
  virtual void Commit() = 0;
  virtual void Rollback() noexcept = 0;
};

// One database connection: use it from one thread at a time.
class Db {
 public:
  explicit Db(std::unique_ptr<DbImpl> impl) : impl_(std::move(impl)) {}

  Dialect dialect() const { return impl_->dialect(); }
  // The file, or the server's address without its password.
  const std::string& path() const { return impl_->path(); }
  // Runs one or more statements that return no rows.
  void Exec(const std::string& sql) { impl_->Exec(sql); }
  Stmt Prepare(std::string_view sql) const { return Stmt(impl_->Prepare(sql)); }
  // The single integer a query returns (0 when no row).
  int64_t QueryInt(std::string_view sql) const {
    Stmt stmt = Prepare(sql);
    return stmt.Step() ? stmt.Int(0) : 0;
  }
  DbImpl& impl() const { return *impl_; }
  // Read snapshots open on this connection (ReadSnapshot nests: the outermost one decides).
  int& read_depth() { return read_depth_; }

 private:
  std::unique_ptr<DbImpl> impl_;
  int read_depth_ = 0;
};

// A write transaction from construction; rolled back on destruction unless Commit() was called.
class Transaction {
 public:
  explicit Transaction(Db& db) : db_(db) { db_.impl().BeginWrite(); }
  ~Transaction() {
    if (!done_) db_.impl().Rollback();
  }
  Transaction(const Transaction&) = delete;
  Transaction& operator=(const Transaction&) = delete;
  void Commit() {
    db_.impl().Commit();
    done_ = true;
  }

 private:
  Db& db_;
  bool done_ = false;
};

// A read transaction (one snapshot of a bank that others go on writing); ended on destruction.
// One made while another is open on the same connection joins it: every read in between sees
// the outer snapshot (a caller can hold one across many Bank calls that each take their own).
class ReadSnapshot {
 public:
  explicit ReadSnapshot(Db& db) : db_(db) {
    if (db_.read_depth() == 0) db_.impl().BeginRead();
    ++db_.read_depth();
  }
  ~ReadSnapshot() {
    if (--db_.read_depth() == 0) db_.impl().Rollback();
  }
  ReadSnapshot(const ReadSnapshot&) = delete;
  ReadSnapshot& operator=(const ReadSnapshot&) = delete;

 private:
  Db& db_;
};

// "(?, ?, ?), (?, ?, ?)": the VALUES of a statement inserting `rows` rows of `columns` values.
inline std::string RowPlaceholders(int rows, int columns) {
  std::string row = "(";
  for (int c = 0; c < columns; ++c) row += c ? ", ?" : "?";
  row += ")";
  std::string out;
  for (int r = 0; r < rows; ++r) out += (r ? ", " : "") + row;
  return out;
}

}  // namespace ss::sql
