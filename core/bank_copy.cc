#include "core/bank_copy.h"

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

#include "core/bank_schema.h"
#include "core/error.h"
#include "core/log.h"
#include "core/sql.h"

namespace ss {
namespace {

// A table as the copy and the digest read it: columns with their kinds (i integer, r real,
// t text, b blob), the order that gives every row a place, and the order rows may be inserted
// in (a mirrored sprite refers to its original).
struct Table {
  const char* name;
  const char* columns;
  const char* kinds;
  const char* key_order;
  const char* insert_order;
};

constexpr Table kTables[] = {
    {"meta", "key, value", "tt", "key", "key"},
    {"sessions", "id, uid, name, created, source",
     "ittt"
     "t",
     "id", "id"},
    {"cameras", "id, session_id, name, cameramodel, width, height", "iittii", "id", "id"},
    {"clips", "id, camera_id, track_id, first_frame, last_frame, complete, complete_seq", "iiiiiii",
     "id", "id"},
    {"sprites",
     "id, clip_id, camera_id, track_id, frame, timestamp_ns, mirrored, mirror_of, ground_x_m, "
     "ground_y_m, "
     "velocity_x_m_s, velocity_y_m_s, mean_r, mean_g, mean_b, area_px, eccentricity, bbox_x, "
     "bbox_y, bbox_w, "
     "bbox_h, billboard_w_px, billboard_h_px, px_per_m, anchor_x_px, anchor_y_px, kind, "
     "heading_rad",
     "iiiiiiii"
     "rrrrrrrrr"
     "iiiiii"
     "rrr"
     "tr",
     "id", "mirrored, id"},
    {"sprite_tags", "sprite_id, tag", "it", "sprite_id, tag", "sprite_id, tag"},
    {"sprite_pixels", "sprite_id, width_px, height_px, codec, data", "iiitb", "sprite_id",
     "sprite_id"},
    {"transitions", "from_sprite, to_sprite, d, cost", "iirr", "from_sprite, to_sprite",
     "from_sprite, to_sprite"},
    {"transition_labels", "from_sprite, to_sprite, label, labelled_at, source", "iittt",
     "from_sprite, to_sprite", "from_sprite, to_sprite"},
};

// The tables whose ids a PostgreSQL bank draws from a sequence.
constexpr const char* kIdTables[] = {"sessions", "cameras", "clips", "sprites"};

struct Value {
  bool null = false;
  int64_t i = 0;
  double r = 0;
  std::string s;  // text or blob bytes
};

Value Read(const sql::Stmt& q, int col, char kind) {
  Value v;
  v.null = q.IsNull(col);
  if (v.null) return v;
  switch (kind) {
    case 'i':
      v.i = q.Int(col);
      break;
    case 'r':
      v.r = q.Real(col);
      break;
    case 't':
      v.s = q.Text(col);
      break;
    default:
      v.s.assign(static_cast<const char*>(q.Blob(col)), q.Bytes(col));
      break;
  }
  return v;
}

class Fnv {
 public:
  void Add(const void* data, size_t size) {
    const auto* p = static_cast<const unsigned char*>(data);
    for (size_t i = 0; i < size; ++i) h_ = (h_ ^ p[i]) * 0x100000001b3ULL;
  }
  void Add(const Value& v, char kind) {
    const unsigned char tag = v.null ? 'n' : static_cast<unsigned char>(kind);
    Add(&tag, 1);
    if (v.null) return;
    if (kind == 'i') Add(&v.i, sizeof(v.i));
    if (kind == 'r') {
      uint64_t bits = 0;
      std::memcpy(&bits, &v.r, sizeof(bits));
      Add(&bits, sizeof(bits));
    }
    if (kind == 't' || kind == 'b') {
      const uint64_t n = v.s.size();
      Add(&n, sizeof(n));
      Add(v.s.data(), v.s.size());
    }
  }
  std::string Hex() const {
    char buffer[17];
    std::snprintf(buffer, sizeof(buffer), "%016llx", static_cast<unsigned long long>(h_));
    return buffer;
  }

 private:
  uint64_t h_ = 0xcbf29ce484222325ULL;
};

BankDigest Digest(const sql::Db& db) {
  BankDigest out;
  Fnv fnv;
  for (const Table& t : kTables) {
    fnv.Add(t.name, std::strlen(t.name) + 1);
    auto q = db.Prepare(std::string("SELECT ") + t.columns + " FROM " + t.name + " ORDER BY " +
                        t.key_order);
    const int n = static_cast<int>(std::strlen(t.kinds));
    int64_t rows = 0;
    while (q.Step()) {
      ++rows;
      for (int c = 0; c < n; ++c) fnv.Add(Read(q, c, t.kinds[c]), t.kinds[c]);
    }
    out.rows[t.name] = rows;
  }
  out.digest = fnv.Hex();
  return out;
}

// Inserts rows many at a time: one statement of up to `per_statement` rows.
class BatchInsert {
 public:
  BatchInsert(sql::Db& db, const Table& t)
      : db_(db), table_(t), width_(static_cast<int>(std::strlen(t.kinds))) {
    // SQLite takes at most 32766 parameters a statement, PostgreSQL 65535.
    per_statement_ = std::max(1, std::min(500, 30000 / width_));
  }
  void Add(std::vector<Value> row) {
    rows_.push_back(std::move(row));
    if (static_cast<int>(rows_.size()) == per_statement_) Flush();
  }
  void Flush() {
    if (rows_.empty()) return;
    std::string sql = std::string("INSERT INTO ") + table_.name + " (" + table_.columns +
                      ") VALUES " + sql::RowPlaceholders(static_cast<int>(rows_.size()), width_);
    if (std::strcmp(table_.name, "meta") == 0)
      sql += " ON CONFLICT (key) DO UPDATE SET value = excluded.value";
    auto q = db_.Prepare(sql);
    int index = 1;
    for (const auto& row : rows_) {
      for (int c = 0; c < width_; ++c, ++index) {
        const Value& v = row[static_cast<size_t>(c)];
        const char kind = table_.kinds[c];
        if (v.null) {
          q.BindNull(index);
        } else if (kind == 'i') {
          q.Bind(index, v.i);
        } else if (kind == 'r') {
          q.Bind(index, v.r);
        } else if (kind == 't') {
          q.Bind(index, std::string_view(v.s));
        } else {
          q.BindBlob(index, v.s.data(), v.s.size());
        }
      }
    }
    q.Step();
    rows_.clear();
  }

 private:
  sql::Db& db_;
  const Table& table_;
  int width_;
  int per_statement_ = 1;
  std::vector<std::vector<Value>> rows_;
};

}  // namespace

BankDigest DigestBank(const std::string& bank) {
  sql::Db db = OpenBankDatabase(bank, /*writable=*/false);
  sql::ReadSnapshot snapshot(db);
  return Digest(db);
}

BankDigest CopyBank(const std::string& from, const std::string& to) {
  if (from == to) throw InputError(to, "bank copy needs two different banks");
  sql::Db src = OpenBankDatabase(from, /*writable=*/false);
  sql::Db dst = OpenBankDatabase(to, /*writable=*/true);
  if (dst.QueryInt("SELECT count(*) FROM sessions") > 0) {
    throw InputError(dst.path(),
                     "holds sessions already: bank copy writes into an empty bank only");
  }
  BankDigest copied;
  {
    sql::ReadSnapshot snapshot(src);
    sql::Transaction tx(dst);
    for (const Table& t : kTables) {
      auto q = src.Prepare(std::string("SELECT ") + t.columns + " FROM " + t.name + " ORDER BY " +
                           t.insert_order);
      const int n = static_cast<int>(std::strlen(t.kinds));
      BatchInsert insert(dst, t);
      int64_t rows = 0;
      while (q.Step()) {
        std::vector<Value> row;
        row.reserve(static_cast<size_t>(n));
        for (int c = 0; c < n; ++c) row.push_back(Read(q, c, t.kinds[c]));
        insert.Add(std::move(row));
        ++rows;
      }
      insert.Flush();
      Log("core.bank")->debug("bank copy: {} rows of {}", rows, t.name);
    }
    if (dst.dialect() == sql::Dialect::kPostgres) {
      // Rows came with their ids: the sequences go on after the largest.
      for (const char* table : kIdTables) {
        dst.Exec(std::string("SELECT setval(pg_get_serial_sequence('") + table +
                 "', 'id'), coalesce(max(id), 0) + 1, "
                 "false) FROM " +
                 table);
      }
    }
    copied = Digest(src);
    tx.Commit();
  }
  BankDigest written = DigestBank(to);
  if (written.digest != copied.digest) {
    throw WorkError(dst.path(), "the copy's digest " + written.digest +
                                    " differs from the source's " + copied.digest);
  }
  return written;
}

}  // namespace ss
