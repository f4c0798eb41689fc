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
// file does not exist. What writes into a bank (ingest) runs it first and refuses a damaged one.
std::vector<std::string> QuickCheckBank(const std::string& path);

}  // namespace ss
