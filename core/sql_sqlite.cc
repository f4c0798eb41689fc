#include "core/sql_sqlite.h"

#include <cerrno>
#include <memory>
#include <system_error>
#include <utility>

#include "core/error.h"

namespace ss::sql {

void Fail(sqlite3* db, int rc, const std::string& path, std::string_view what) {
  const int thread_errno = errno;  // the failed write's, before anything here makes calls
  std::string message = db ? sqlite3_errmsg(db) : sqlite3_errstr(rc);
  // A failed write says why: "disk I/O error" alone hides a full disk (ENOSPC) or a file past
  // its size limit (EFBIG). SQLite's own record of the call's errno is often 0 by the time the
  // statement returns (a rollback ran after it); the thread's errno still holds it.
  if ((rc & 0xff) == SQLITE_IOERR || (rc & 0xff) == SQLITE_FULL) {
    int err = db ? sqlite3_system_errno(db) : 0;
    if (err == 0) err = thread_errno;
    if (err != 0) message += " (" + std::error_code(err, std::generic_category()).message() + ")";
  }
  const std::string reason = std::string(what) + ": " + message;
  switch (rc & 0xff) {
    case SQLITE_NOTADB:
      throw InputError(path, "not a SQLite database (" + reason + ")");
    case SQLITE_CORRUPT:
      throw CorruptError(path, "the database is damaged (" + reason + ")");
    case SQLITE_BUSY:
    case SQLITE_LOCKED:
      throw BusyError(path, reason);
    default:
      throw WorkError(path, reason);
  }
}

namespace {

class SqliteStmt final : public StmtImpl {
 public:
  SqliteStmt(sqlite3* db, std::string_view sql, const std::string& path) : db_(db), path_(path) {
    const int rc =
        sqlite3_prepare_v2(db, sql.data(), static_cast<int>(sql.size()), &stmt_, nullptr);
    if (rc != SQLITE_OK) Fail(db, rc, path, "prepare '" + std::string(sql.substr(0, 60)) + "'");
  }
  ~SqliteStmt() override { sqlite3_finalize(stmt_); }
  SqliteStmt(const SqliteStmt&) = delete;
  SqliteStmt& operator=(const SqliteStmt&) = delete;

  void Bind(int index, int64_t value) override { Check(sqlite3_bind_int64(stmt_, index, value)); }
  void Bind(int index, double value) override { Check(sqlite3_bind_double(stmt_, index, value)); }
  void Bind(int index, std::string_view text) override {
    Check(sqlite3_bind_text(stmt_, index, text.data(), static_cast<int>(text.size()),
                            SQLITE_TRANSIENT));
  }
  void BindBlob(int index, const void* data, size_t size) override {
    Check(sqlite3_bind_blob64(stmt_, index, data, size, SQLITE_TRANSIENT));
  }
  void BindNull(int index) override { Check(sqlite3_bind_null(stmt_, index)); }

  bool Step() override {
    const int rc = sqlite3_step(stmt_);
    if (rc == SQLITE_ROW) return true;
    if (rc == SQLITE_DONE) {
      changes_ = sqlite3_changes64(db_);
      return false;
    }
    const std::string sql = sqlite3_sql(stmt_) ? sqlite3_sql(stmt_) : "";
    sqlite3_reset(stmt_);
    Fail(db_, rc, path_, "'" + sql.substr(0, 60) + "'");
  }
  void Reset() override {
    sqlite3_reset(stmt_);
    sqlite3_clear_bindings(stmt_);
  }

  int64_t Int(int col) const override { return sqlite3_column_int64(stmt_, col); }
  double Real(int col) const override { return sqlite3_column_double(stmt_, col); }
  bool IsNull(int col) const override { return sqlite3_column_type(stmt_, col) == SQLITE_NULL; }
  std::string Text(int col) const override {
    const auto* text = sqlite3_column_text(stmt_, col);
    if (!text) return {};
    return std::string(reinterpret_cast<const char*>(text),
                       static_cast<size_t>(sqlite3_column_bytes(stmt_, col)));
  }
  const void* Blob(int col) const override { return sqlite3_column_blob(stmt_, col); }
  size_t Bytes(int col) const override {
    return static_cast<size_t>(sqlite3_column_bytes(stmt_, col));
  }
  int64_t Changes() const override { return changes_; }

 private:
  void Check(int rc) {
    if (rc != SQLITE_OK) Fail(db_, rc, path_, "bind");
  }

  sqlite3_stmt* stmt_ = nullptr;
  sqlite3* db_ = nullptr;
  std::string path_;
  int64_t changes_ = 0;
};

class SqliteDb final : public DbImpl {
 public:
  SqliteDb(const std::string& path, int flags) : path_(path) {
    const int rc = sqlite3_open_v2(path.c_str(), &db_, flags, nullptr);
    if (rc != SQLITE_OK) {
      const std::string message = db_ ? sqlite3_errmsg(db_) : sqlite3_errstr(rc);
      sqlite3_close_v2(db_);
      db_ = nullptr;
      if ((rc & 0xff) == SQLITE_CANTOPEN) throw InputError(path, "cannot open (" + message + ")");
      throw WorkError(path, "cannot open (" + message + ")");
    }
    sqlite3_extended_result_codes(db_, 1);
  }
  ~SqliteDb() override { sqlite3_close_v2(db_); }
  SqliteDb(const SqliteDb&) = delete;
  SqliteDb& operator=(const SqliteDb&) = delete;

  sqlite3* get() const { return db_; }
  Dialect dialect() const override { return Dialect::kSqlite; }
  const std::string& path() const override { return path_; }
  void Exec(const std::string& sql) override {
    char* error = nullptr;
    const int rc = sqlite3_exec(db_, sql.c_str(), nullptr, nullptr, &error);
    if (rc != SQLITE_OK) {
      sqlite3_free(error);
      Fail(db_, rc, path_, "'" + sql.substr(0, 60) + "'");
    }
  }
  std::unique_ptr<StmtImpl> Prepare(std::string_view sql) override {
    return std::make_unique<SqliteStmt>(db_, sql, path_);
  }
  void BeginWrite() override { Exec("BEGIN IMMEDIATE"); }
  void BeginRead() override { Exec("BEGIN"); }
  void Commit() override { Exec("COMMIT"); }
  void Rollback() noexcept override { sqlite3_exec(db_, "ROLLBACK", nullptr, nullptr, nullptr); }

 private:
  sqlite3* db_ = nullptr;
  std::string path_;
};

}  // namespace

Db OpenSqlite(const std::string& path, int flags) {
  return Db(std::make_unique<SqliteDb>(path, flags));
}

sqlite3* SqliteHandle(const Db& db) {
  auto* sqlite = dynamic_cast<SqliteDb*>(&db.impl());
  if (!sqlite) throw WorkError(db.path(), "not a SQLite database");
  return sqlite->get();
}

}  // namespace ss::sql
