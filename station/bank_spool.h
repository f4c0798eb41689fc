#pragma once
// The station's spool: clip batches the bank could not take (its PostgreSQL server gone, a
// SQLite file locked past every retry) wait here on disk, one file each, written and fsynced
// before they count as kept, and are taken back oldest first when the bank answers again.
// A batch appended twice is harmless (the bank keeps a sprite it already has), so a crash
// between an append and the file's removal loses nothing and doubles nothing.
// Used by the station's writer thread only.
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "pipeline/run/clip_batcher.h"

namespace ss {

class BankSpool {
 public:
  // Opens (making it if missing) `dir` and takes in the batches an earlier run left there.
  // WorkError naming the folder when it cannot be made.
  BankSpool(std::string dir, int64_t max_bytes);

  // Keeps `batch` on disk. False, with nothing written, when it would take the spool past
  // max_bytes; WorkError naming the file when it cannot be written (a full disk).
  bool Push(const ClipBatch& batch);
  // The oldest batch, or nullopt when the spool is empty. A file that cannot be read back is
  // moved to DIR/damaged/ (kept for a person to look at) and the next one is tried.
  std::optional<ClipBatch> Front();
  // Removes the oldest batch (after the bank took it).
  void PopFront();
  // Moves the oldest batch to DIR/damaged/ (the bank refused it for what it holds: kept for a
  // person to look at, never dropped).
  void SetAsideFront(const std::string& why);

  bool empty() const { return files_.empty(); }
  size_t batches() const { return files_.size(); }
  int64_t bytes() const { return bytes_; }
  const std::string& dir() const { return dir_; }

  // The bytes of a batch in the spool's format (CBOR: every field, pixels zstd-compressed as
  // in the bank) and back; InputError naming `what` when the bytes are not a batch.
  static std::vector<uint8_t> Encode(const ClipBatch& batch);
  static ClipBatch Decode(const std::vector<uint8_t>& bytes, const std::string& what);

 private:
  void MoveToDamaged(const std::string& why);

  struct File {
    std::string path;
    int64_t bytes = 0;
  };
  std::string dir_;
  int64_t max_bytes_;
  std::vector<File> files_;  // oldest first
  int64_t bytes_ = 0;
  uint64_t next_ = 1;
};

}  // namespace ss
