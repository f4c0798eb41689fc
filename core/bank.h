#pragma once
// The sprite bank (schema in docs/formats.md): one SQLite file in WAL mode (a path), or one
// PostgreSQL database shared by many stations (an address `postgresql://...`, docs/scaling.md);
// every command that takes a bank takes either. Writers (BankWriter) append clips batch by
// batch: one at a time for SQLite, any number at once for PostgreSQL; any number of readers
// (Bank, each its own connection, in threads or processes) read meanwhile and see only
// complete clips. A Bank object is one connection: use it from one thread at a time.
#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "core/bank_records.h"

namespace ss {

namespace sql {
class Db;
class ReadSnapshot;
}  // namespace sql

// Figures for `bank info`.
struct BankCounts {
  int schema_version = 0;
  int64_t sessions = 0, cameras = 0;
  int64_t clips = 0, clips_complete = 0;
  int64_t sprites = 0, mirrors = 0;         // all rows; `mirrors` of them are mirrored copies
  int64_t sprites_visible = 0;              // sprites in complete clips (what readers see)
  int64_t pixel_rows = 0, pixel_bytes = 0;  // compressed billboard bytes
  int64_t transitions = 0;
  int64_t tags = 0, tagged_sprites = 0;  // distinct tag names, sprites with a tag
  int64_t file_bytes = 0, wal_bytes = 0;
};

class Bank {
 public:
  // Opens an existing bank read-only. InputError naming the file when it is missing,
  // not a SQLite database, not a sprite bank, or of another schema version; BusyError when a
  // PostgreSQL server cannot be reached.
  explicit Bank(const std::string& path);
  virtual ~Bank();
  Bank(Bank&&) noexcept;
  Bank& operator=(Bank&&) noexcept;

  // The file, or the server's address without its password.
  const std::string& path() const { return path_; }
  int schema_version() const;
  bool is_postgres() const;

  std::vector<SessionRecord> ListSessions() const;
  std::vector<CameraRecord> ListCameras() const;
  // Complete clips ordered by complete_seq; only those completed after `completed_after_seq`.
  std::vector<ClipRecord> ListClips(int64_t completed_after_seq = 0) const;
  // Every clip, complete or not (for verify and diagnostics).
  std::vector<ClipRecord> ListAllClips() const;
  // Features of the sprites of complete clips completed after `completed_after_seq`.
  std::vector<SpriteFeatures> LoadFeatures(int64_t completed_after_seq = 0) const;
  // One sprite with every field and its tags (pixels not loaded). InputError if unknown.
  SpriteRecord LoadSprite(int64_t id) const;
  // A sprite's billboard, decompressed (a mirrored sprite's is its original's, flipped).
  SpritePixels LoadPixels(int64_t id) const;
  std::vector<TransitionRecord> LoadTransitions() const;
  // How many rows the transition table holds (LoadTransitions' size, without reading them).
  int64_t TransitionCount() const;
  // Transitions leaving `from_sprite`.
  std::vector<TransitionRecord> LoadTransitionsFrom(int64_t from_sprite) const;
  // Transitions arriving at `to_sprite`.
  std::vector<TransitionRecord> LoadTransitionsTo(int64_t to_sprite) const;
  // A clip's original sprites (no mirrors, no pixels) with their tags, by frame.
  std::vector<SpriteRecord> LoadClipSprites(int64_t clip_id) const;
  // The ids of a clip's sprites at frames first..last (inclusive), with their mirrored copies.
  std::vector<int64_t> ClipSpriteIds(int64_t clip_id, int64_t first_frame,
                                     int64_t last_frame) const;
  // Original sprites per clip id, and per clip the number of its originals with each tag.
  std::map<int64_t, int64_t> CountClipSprites() const;
  std::map<int64_t, std::map<std::string, int64_t>> CountClipTags() const;
  std::vector<int64_t> SpritesTagged(const std::string& tag) const;
  std::optional<std::string> GetMeta(const std::string& key) const;
  BankCounts Counts() const;
  // The billboard scales (px_per_m) its sprites are stored at, smallest first: empty for a bank
  // without sprites, one for a sound bank (one bank keeps one scale).
  std::vector<double> BillboardScales() const;
  // The labels of sprite pairs (transition_labels), in the order they were made.
  std::vector<TransitionLabelRecord> LoadTransitionLabels() const;
  // Labels per kind: {"yes": n, "no": n, "skip": n} (kinds without labels are 0).
  std::map<std::string, int64_t> CountTransitionLabels() const;

 protected:
  enum class Mode { kReadOnly, kReadWrite };
  Bank(const std::string& path, Mode mode);
  sql::Db& db() const { return *db_; }

 private:
  struct ReadCache;  // prepared statements and the pixel codec, made on first use
  ReadCache& cache() const;

  std::string path_;
  std::unique_ptr<sql::Db> db_;
  mutable std::unique_ptr<ReadCache> cache_;
  friend class BankSnapshot;
};

// While it lives, every read through `bank` sees one committed state of the bank, however much
// other writers commit meanwhile (a read transaction: SQLite's WAL snapshot, PostgreSQL's
// REPEATABLE READ). The offline optimizer reads its whole graph inside one.
class BankSnapshot {
 public:
  explicit BankSnapshot(const Bank& bank);
  ~BankSnapshot();
  BankSnapshot(const BankSnapshot&) = delete;
  BankSnapshot& operator=(const BankSnapshot&) = delete;

 private:
  std::unique_ptr<sql::ReadSnapshot> snapshot_;
};

// What one appended batch did.
struct AppendResult {
  int64_t clip_id = 0;
  std::vector<int64_t> sprite_ids;  // in the order of the batch
  int64_t inserted = 0;             // new sprites; the rest were already in the bank
};

// The writer: creates the bank if needed and upgrades an older schema in place.
// Each call is one transaction: after a crash every call that returned is in the bank.
class BankWriter : public Bank {
 public:
  explicit BankWriter(const std::string& path);
  ~BankWriter() override;
  BankWriter(BankWriter&&) noexcept;
  BankWriter& operator=(BankWriter&&) noexcept;

  // Registers a session (by uid) and returns its id; the same uid returns the same id.
  int64_t AddSession(const SessionRecord& session);
  // Renames a session (its uid stays); WorkError for an unknown id.
  void RenameSession(int64_t session_id, const std::string& name);
  // Registers a camera of a session (by name) and returns its id.
  int64_t AddCamera(int64_t session_id, const CameraRecord& camera);
  // Appends one batch of a clip's sprites. The clip (camera_id, track_id, first_frame)
  // is created by its first batch; last_frame grows to cover the batch; clip.complete
  // marks this batch as the clip's last. Sprites already stored (same camera, frame,
  // track, mirrored) are kept as they are. A mirrored sprite is linked to the original
  // of its frame (in this batch or stored before). Throws WorkError on a bad batch.
  AppendResult AppendClipBatch(const ClipRecord& clip, const std::vector<SpriteRecord>& sprites);
  // Inserts or replaces transitions, all in one transaction.
  void UpsertTransitions(const std::vector<TransitionRecord>& transitions);
  void ClearTransitions();
  // Keeps out of each of `from_sprites` only its `keep` cheapest transitions (by cost, then
  // to_sprite: docs/transitions.md "At most K out of a sprite") and deletes the rest, in one
  // transaction. Returns how many went. With `bars`, also gives the worst kept transition of
  // every named sprite that now holds `keep`: a transition after it can never be kept.
  int64_t PruneTransitions(std::span<const int64_t> from_sprites, int keep,
                           std::vector<TransitionRecord>* bars = nullptr);
  // Adds/removes a tag on sprites; InputError naming the first unknown sprite id.
  void Tag(const std::vector<int64_t>& sprite_ids, const std::string& tag);
  void Untag(const std::vector<int64_t>& sprite_ids, const std::string& tag);
  void SetMeta(const std::string& key, const std::string& value);
  // Sets `key` only if the bank has no value for it, and returns the value the bank keeps:
  // `value`, or the one an earlier (or concurrent) writer set first.
  std::string KeepMeta(const std::string& key, const std::string& value);
  // Stores (or replaces) the label of from_sprite -> to_sprite. InputError naming the bank and
  // the sprite for an unknown sprite id, InputError("label", ...) for a label other than
  // yes / no / skip or a sprite paired with itself.
  void SetTransitionLabel(const TransitionLabelRecord& label);
  // Removes a label; false when there was none.
  bool RemoveTransitionLabel(int64_t from_sprite, int64_t to_sprite);

 private:
  // AppendClipBatch's sprites: one statement each (SQLite, in-process), or a few statements of
  // many rows (PostgreSQL, where every statement is a round trip to the server).
  void AppendSpritesOneByOne(const ClipRecord& clip, int64_t clip_id,
                             const std::vector<SpriteRecord>& sprites, const std::string& where,
                             AppendResult* out);
  void AppendSpritesManyRows(const ClipRecord& clip, int64_t clip_id,
                             const std::vector<SpriteRecord>& sprites, const std::string& where,
                             AppendResult* out);

  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace ss
