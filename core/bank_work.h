#pragma once
// Units of transition work shared by any number of workers on any hosts (a PostgreSQL bank
// only: docs/scaling.md). A unit is one complete clip: its sprites against every sprite of the
// clips completed before it (and with it). Units live in the table transition_work beside the
// bank's tables (coordination, not content: bank copy and bank digest leave it out). A worker
// claims the oldest pending unit whose lease is free with FOR UPDATE SKIP LOCKED, so two never
// take the same one; a worker that dies loses its lease (the database's clock) and another
// takes the unit again. Storing a unit twice stores the same rows.
#include <cstdint>
#include <memory>
#include <optional>
#include <string>

namespace ss {

namespace sql {
class Db;
}

struct WorkUnit {
  int64_t clip_id = 0;
  int64_t complete_seq = 0;
  int attempts = 0;  // claims so far, this one included
};

struct WorkCounts {
  int64_t pending = 0, leased = 0, done = 0;
};

class BankWorkQueue {
 public:
  // InputError naming the bank when it is not a PostgreSQL bank; makes the table if missing.
  explicit BankWorkQueue(const std::string& bank);
  ~BankWorkQueue();
  BankWorkQueue(const BankWorkQueue&) = delete;
  BankWorkQueue& operator=(const BankWorkQueue&) = delete;

  // Adds a unit for every complete clip that has none yet; returns how many were added.
  int64_t Register();
  // Claims the oldest pending unit whose lease has run out (or was never taken) for `worker`
  // until `lease_s` seconds from now.
  std::optional<WorkUnit> Claim(const std::string& worker, double lease_s);
  // Marks a unit done.
  void Done(int64_t clip_id);
  WorkCounts Counts() const;

 private:
  std::unique_ptr<sql::Db> db_;
  int64_t registered_seq_ = 0;
};

}  // namespace ss
