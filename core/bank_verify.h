#pragma once
// `bank verify`: checks a sprite bank's file, schema and invariants (docs/formats.md).
#include <cstdint>
#include <string>
#include <vector>

namespace ss {

struct BankVerifyReport {
  std::string path;
  int schema_version = 0;
  int64_t clips_checked = 0, sprites_checked = 0, pixel_blobs_checked = 0;
  std::vector<std::string> problems;  // one line each; empty when the bank is sound
  bool ok() const { return problems.empty(); }
};

// Opens `path` read-only and checks: SQLite integrity and foreign keys, the schema
// (version, application id, every table and index as this version defines them; for a
// PostgreSQL bank its tables, columns and indexes: the server keeps pages and keys whole),
// clip frame ranges, mirror links, every pixel blob decompressing to its stated size.
// Throws InputError when the file is missing, not a bank, or of another schema version.
BankVerifyReport VerifyBank(const std::string& path);

// SQLite's quick check of an existing bank file (pages and indexes well formed; seconds for a
// large bank, much less than VerifyBank): the problems it reports, empty when it passes or the
// file does not exist.
std::vector<std::string> QuickCheckBank(const std::string& path);

// What writes into an existing bank (ingest, `bank tag` and `upgrade`, `transitions`, the
// station) calls this first: throws InputError naming the file and its first damage when the
// quick check fails, so nothing is written. A damaged bank stays readable by `bank export`, and
// `bank verify` says where it is damaged; appending could only spread the damage.
void RefuseDamagedBank(const std::string& path);

}  // namespace ss
