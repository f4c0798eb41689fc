#pragma once
// `bank copy` and `bank digest`: moving a bank between SQLite and PostgreSQL (either
// direction), and a digest of its content that is the same for the same bank in either.
#include <cstdint>
#include <map>
#include <string>

namespace ss {

// The content of a bank: every row of every table (meta, sessions, cameras, clips, sprites,
// tags, pixel blobs as stored, transitions, labels) in key order, each value with its kind and
// exact bits (FNV-1a, 64 bits, in hex). Equal digests: the same ids, fields, pixels and
// transitions; it is a check against mistakes, not against someone forging a bank.
struct BankDigest {
  std::string digest;
  std::map<std::string, int64_t> rows;  // per table
};
// Reads one snapshot of `bank` (a file or a postgresql:// address).
BankDigest DigestBank(const std::string& bank);

// Copies every row of `from` into `to` (made if missing, upgraded if older), keeping every id,
// in one transaction on `to` from one snapshot of `from` (a bank being written may be copied).
// InputError naming `to` when it already holds sessions (a copy never merges).
// Returns the digest, checked equal on both sides; WorkError if they differ.
BankDigest CopyBank(const std::string& from, const std::string& to);

}  // namespace ss
