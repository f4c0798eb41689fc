#include "core/sql_postgres.h"

#include <libpq-fe.h>

#include <charconv>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <optional>
#include <vector>

#include "core/error.h"
#include "core/log.h"

namespace ss::sql {

bool IsPostgresAddress(std::string_view address) {
  return address.rfind("postgresql://", 0) == 0 || address.rfind("postgres://", 0) == 0;
}

std::string RedactAddress(const std::string& address) {
  std::string out = address;
  // postgresql://user:secret@host -> postgresql://user:***@host
  const size_t scheme = out.find("://");
  if (scheme != std::string::npos) {
    const size_t start = scheme + 3;
    const size_t at = out.find('@', start);
    const size_t slash = out.find('/', start);
    if (at != std::string::npos && (slash == std::string::npos || at < slash)) {
      const size_t colon = out.find(':', start);
      if (colon != std::string::npos && colon < at) out.replace(colon + 1, at - colon - 1, "***");
    }
  }
  // ...?password=secret&... -> password=***
  for (size_t pos = out.find("password="); pos != std::string::npos;
       pos = out.find("password=", pos + 1)) {
    const size_t value = pos + 9;
    const size_t end = out.find('&', value);
    out.replace(value, (end == std::string::npos ? out.size() : end) - value, "***");
  }
  return out;
}

namespace {

std::string Trim(std::string text) {
  while (!text.empty() && (text.back() == '\n' || text.back() == ' ')) text.pop_back();
  return text;
}

// Throws the error that matches a failed result (see the file comment).
[[noreturn]] void FailResult(PGconn* conn, const PGresult* result, const std::string& path,
                             std::string_view what) {
  const char* state = result ? PQresultErrorField(result, PG_DIAG_SQLSTATE) : nullptr;
  const std::string code = state ? state : "";
  std::string message = Trim(result ? PQresultErrorMessage(result) : "");
  if (message.empty()) message = Trim(PQerrorMessage(conn));
  const std::string reason = std::string(what) + ": " + message;
  const bool lost = PQstatus(conn) == CONNECTION_BAD;
  if (lost || code.rfind("08", 0) == 0 || code.rfind("57P0", 0) == 0 || code.rfind("40", 0) == 0 ||
      code == "55P03" || code == "53300") {
    throw BusyError(path, reason);
  }
  if (code == "XX001" || code == "XX002")
    throw CorruptError(path, "the database is damaged (" + reason + ")");
  throw WorkError(path, reason);
}

struct ResultDeleter {
  void operator()(PGresult* r) const { PQclear(r); }
};
using Result = std::unique_ptr<PGresult, ResultDeleter>;

// `?` placeholders (outside quotes) become PostgreSQL's `$1, $2, ...`; returns their count.
std::string Placeholders(std::string_view sql, int* count) {
  std::string out;
  out.reserve(sql.size() + 16);
  char quote = 0;
  int n = 0;
  for (char c : sql) {
    if (quote) {
      if (c == quote) quote = 0;
      out += c;
    } else if (c == '\'' || c == '"') {
      quote = c;
      out += c;
    } else if (c == '?') {
      out += '$' + std::to_string(++n);
    } else {
      out += c;
    }
  }
  *count = n;
  return out;
}

int Hex(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  return -1;
}

class PostgresDb;

class PostgresStmt final : public StmtImpl {
 public:
  PostgresStmt(PostgresDb& db, std::string_view sql);

  void Bind(int index, int64_t value) override { Set(index, std::to_string(value), 0); }
  void Bind(int index, double value) override {
    char buffer[32];
    const auto end = std::to_chars(buffer, buffer + sizeof(buffer), value);  // shortest exact
    Set(index, std::string(buffer, end.ptr), 0);
  }
  void Bind(int index, std::string_view text) override { Set(index, std::string(text), 0); }
  void BindBlob(int index, const void* data, size_t size) override {
    Set(index, std::string(static_cast<const char*>(data), size), 1);
  }
  void BindNull(int index) override {
    Check(index);
    values_[index - 1].reset();
  }

  bool Step() override;
  void Reset() override {
    result_.reset();
    row_ = -1;
    blob_row_ = blob_col_ = -1;
    for (auto& v : values_) v.reset();
    std::fill(formats_.begin(), formats_.end(), 0);
  }

  int64_t Int(int col) const override {
    const char* text = Value(col);
    int64_t value = 0;
    if (*text == 't') return 1;  // a boolean
    std::from_chars(text, text + std::strlen(text), value);
    return value;
  }
  double Real(int col) const override { return std::strtod(Value(col), nullptr); }
  bool IsNull(int col) const override { return PQgetisnull(result_.get(), row_, col) != 0; }
  std::string Text(int col) const override {
    if (IsNull(col)) return {};
    return std::string(PQgetvalue(result_.get(), row_, col),
                       static_cast<size_t>(PQgetlength(result_.get(), row_, col)));
  }
  const void* Blob(int col) const override {
    Decode(col);
    return blob_.data();
  }
  size_t Bytes(int col) const override {
    if (PQftype(result_.get(), col) != kByteaOid)
      return static_cast<size_t>(PQgetlength(result_.get(), row_, col));
    Decode(col);
    return blob_.size();
  }
  int64_t Changes() const override { return changes_; }

 private:
  static constexpr Oid kByteaOid = 17;

  void Check(int index) const {
    if (index < 1 || index > static_cast<int>(values_.size())) {
      throw WorkError("sql", "bind index " + std::to_string(index) + " outside 1.." +
                                 std::to_string(values_.size()));
    }
  }
  void Set(int index, std::string value, int format) {
    Check(index);
    values_[index - 1] = std::move(value);
    formats_[index - 1] = format;
  }
  const char* Value(int col) const { return PQgetvalue(result_.get(), row_, col); }
  // The current row's bytea column `col`, from its hex text form ("\x0a1b...").
  void Decode(int col) const {
    if (blob_row_ == row_ && blob_col_ == col) return;
    const char* text = Value(col);
    const size_t length = static_cast<size_t>(PQgetlength(result_.get(), row_, col));
    blob_.clear();
    if (length >= 2 && text[0] == '\\' && text[1] == 'x') {
      blob_.reserve((length - 2) / 2);
      for (size_t i = 2; i + 1 < length; i += 2) {
        blob_.push_back(static_cast<unsigned char>(Hex(text[i]) * 16 + Hex(text[i + 1])));
      }
    } else {
      blob_.assign(text, text + length);
    }
    blob_row_ = row_;
    blob_col_ = col;
  }

  PostgresDb& db_;
  std::string sql_;
  std::vector<std::optional<std::string>> values_;
  std::vector<int> formats_;
  Result result_;
  int row_ = -1;
  int64_t changes_ = 0;
  mutable std::vector<unsigned char> blob_;
  mutable int blob_row_ = -1, blob_col_ = -1;
};

class PostgresDb final : public DbImpl {
 public:
  PostgresDb(const std::string& address, bool read_only)
      : path_(RedactAddress(address)), read_only_(read_only) {
    const char* keys[] = {"connect_timeout", "fallback_application_name", "dbname", nullptr};
    const char* values[] = {"10", "spritestation", address.c_str(), nullptr};
    conn_ = PQconnectdbParams(keys, values, /*expand_dbname=*/1);
    if (!conn_ || PQstatus(conn_) != CONNECTION_OK) {
      const std::string message = conn_ ? Trim(PQerrorMessage(conn_)) : "out of memory";
      PQfinish(conn_);
      conn_ = nullptr;
      throw BusyError(path_, "cannot connect (" + message + ")");
    }
    Configure();
  }
  ~PostgresDb() override { PQfinish(conn_); }
  PostgresDb(const PostgresDb&) = delete;
  PostgresDb& operator=(const PostgresDb&) = delete;

  PGconn* conn() const { return conn_; }
  Dialect dialect() const override { return Dialect::kPostgres; }
  const std::string& path() const override { return path_; }

  void Exec(const std::string& sql) override {
    Result r(PQexec(conn_, sql.c_str()));
    const auto status = PQresultStatus(r.get());
    if (status != PGRES_COMMAND_OK && status != PGRES_TUPLES_OK)
      FailResult(conn_, r.get(), path_, Brief(sql));
  }
  std::unique_ptr<StmtImpl> Prepare(std::string_view sql) override {
    return std::make_unique<PostgresStmt>(*this, sql);
  }
  void BeginWrite() override {
    Reconnect();
    Exec("BEGIN");
  }
  void BeginRead() override {
    Reconnect();
    Exec("BEGIN ISOLATION LEVEL REPEATABLE READ READ ONLY");
  }
  void Commit() override { Exec("COMMIT"); }
  void Rollback() noexcept override {
    if (PQstatus(conn_) == CONNECTION_OK) PQclear(PQexec(conn_, "ROLLBACK"));
  }

  static std::string Brief(std::string_view sql) {
    return "'" + std::string(sql.substr(0, 60)) + "'";
  }

 private:
  // Once per connection: quiet notices (IF NOT EXISTS), and read-only when asked.
  void Configure() {
    PQsetNoticeProcessor(
        conn_,
        [](void*, const char* message) {
          Log("core.bank")->debug("postgresql: {}", Trim(message));
        },
        nullptr);
    Exec("SET client_min_messages = warning");
    if (read_only_) Exec("SET default_transaction_read_only = on");
  }
  // A connection lost since the last transaction is made again (statements keep no server state).
  void Reconnect() {
    if (PQstatus(conn_) == CONNECTION_OK) return;
    PQreset(conn_);
    if (PQstatus(conn_) != CONNECTION_OK) {
      throw BusyError(
          path_, "connection lost and not re-established (" + Trim(PQerrorMessage(conn_)) + ")");
    }
    Log("core.bank")->info("{}: connection re-established", path_);
    Configure();
  }

  PGconn* conn_ = nullptr;
  std::string path_;
  bool read_only_ = false;
};

PostgresStmt::PostgresStmt(PostgresDb& db, std::string_view sql) : db_(db) {
  int count = 0;
  sql_ = Placeholders(sql, &count);
  values_.resize(static_cast<size_t>(count));
  formats_.assign(static_cast<size_t>(count), 0);
}

bool PostgresStmt::Step() {
  if (!result_) {
    const int n = static_cast<int>(values_.size());
    std::vector<const char*> values(values_.size());
    std::vector<int> lengths(values_.size());
    for (size_t i = 0; i < values_.size(); ++i) {
      values[i] = values_[i] ? values_[i]->data() : nullptr;
      lengths[i] = values_[i] ? static_cast<int>(values_[i]->size()) : 0;
    }
    result_.reset(PQexecParams(db_.conn(), sql_.c_str(), n, nullptr, values.data(), lengths.data(),
                               formats_.data(),
                               /*resultFormat=*/0));
    const auto status = PQresultStatus(result_.get());
    if (status != PGRES_COMMAND_OK && status != PGRES_TUPLES_OK) {
      Result failed = std::move(result_);
      FailResult(db_.conn(), failed.get(), db_.path(), PostgresDb::Brief(sql_));
    }
    const char* tuples = PQcmdTuples(result_.get());
    changes_ = (tuples && *tuples) ? std::atoll(tuples) : 0;
    row_ = -1;
    blob_row_ = blob_col_ = -1;
  }
  ++row_;
  return row_ < PQntuples(result_.get());
}

}  // namespace

Db OpenPostgres(const std::string& address, bool read_only) {
  return Db(std::make_unique<PostgresDb>(address, read_only));
}

}  // namespace ss::sql
