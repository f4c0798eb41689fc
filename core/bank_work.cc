#include "core/bank_work.h"

#include "core/bank_schema.h"
#include "core/error.h"
#include "core/sql.h"
#include "core/sql_postgres.h"

namespace ss {
namespace {

// The database's clock in milliseconds: every host's leases are measured on one clock.
constexpr const char* kNowMs = "(extract(epoch from clock_timestamp()) * 1000)::bigint";

}  // namespace

BankWorkQueue::BankWorkQueue(const std::string& bank) {
  if (!sql::IsPostgresAddress(bank)) {
    throw InputError(bank,
                     "shared transition work needs a PostgreSQL bank (postgresql://...); "
                     "for a file, run `spritestation transitions BANK`");
  }
  db_ = std::make_unique<sql::Db>(OpenBankDatabase(bank, /*writable=*/true));
  sql::Transaction tx(*db_);
  db_->Exec("SELECT pg_advisory_xact_lock(" + std::to_string(kBankApplicationId) + ", 3)");
  db_->Exec(
      "CREATE TABLE IF NOT EXISTS transition_work ("
      " clip_id BIGINT PRIMARY KEY REFERENCES clips(id) ON DELETE CASCADE,"
      " complete_seq BIGINT NOT NULL,"
      " done SMALLINT NOT NULL DEFAULT 0 CHECK (done IN (0, 1)),"
      " worker TEXT NOT NULL DEFAULT '',"
      " lease_until_ms BIGINT NOT NULL DEFAULT 0,"
      " attempts INTEGER NOT NULL DEFAULT 0);"
      "CREATE INDEX IF NOT EXISTS transition_work_pending ON transition_work (complete_seq) WHERE "
      "done = 0");
  tx.Commit();
}

BankWorkQueue::~BankWorkQueue() = default;

int64_t BankWorkQueue::Register() {
  auto q = db_->Prepare(
      "INSERT INTO transition_work (clip_id, complete_seq) SELECT id, complete_seq FROM clips "
      "WHERE complete = 1 AND complete_seq > ? ON CONFLICT (clip_id) DO NOTHING");
  q.Bind(1, registered_seq_).Step();
  const int64_t added = q.Changes();
  registered_seq_ = db_->QueryInt("SELECT coalesce(max(complete_seq), 0) FROM transition_work");
  return added;
}

std::optional<WorkUnit> BankWorkQueue::Claim(const std::string& worker, double lease_s) {
  auto q = db_->Prepare(
      std::string("UPDATE transition_work SET worker = ?, lease_until_ms = ") + kNowMs +
      " + ?, attempts = attempts + 1 WHERE clip_id = (SELECT clip_id FROM transition_work "
      "WHERE done = 0 AND lease_until_ms < " +
      kNowMs +
      " ORDER BY complete_seq LIMIT 1 FOR UPDATE SKIP LOCKED) "
      "RETURNING clip_id, complete_seq, attempts");
  q.Bind(1, worker).Bind(2, static_cast<int64_t>(lease_s * 1000));
  if (!q.Step()) return std::nullopt;
  return WorkUnit{q.Int(0), q.Int(1), static_cast<int>(q.Int(2))};
}

void BankWorkQueue::Done(int64_t clip_id) {
  auto q = db_->Prepare("UPDATE transition_work SET done = 1 WHERE clip_id = ?");
  q.Bind(1, clip_id).Step();
}

WorkCounts BankWorkQueue::Counts() const {
  WorkCounts c;
  auto q = db_->Prepare(
      std::string("SELECT coalesce(sum(CASE WHEN done = 0 AND lease_until_ms < ") + kNowMs +
      " THEN 1 ELSE 0 END), 0), coalesce(sum(CASE WHEN done = 0 AND lease_until_ms >= " + kNowMs +
      " THEN 1 ELSE 0 END), 0), coalesce(sum(done), 0) FROM transition_work");
  if (q.Step()) c = {q.Int(0), q.Int(1), q.Int(2)};
  return c;
}

}  // namespace ss
