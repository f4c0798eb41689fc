#include "core/bank.h"

#include <algorithm>
#include <filesystem>
#include <map>
#include <system_error>
#include <utility>

#include <opencv2/core.hpp>

#include "core/bank_pixels.h"
#include "core/bank_schema.h"
#include "core/error.h"
#include "core/sql.h"
#include "core/sql_postgres.h"
#include "core/sql_sqlite.h"

namespace ss {
namespace {

namespace fs = std::filesystem;

// The sprite columns in the order ReadSprite reads them; the bank assigns the id.
#define SS_SPRITE_FIELDS                                                                    \
  "clip_id, camera_id, track_id, frame, timestamp_ns, mirrored, mirror_of, ground_x_m, "    \
  "ground_y_m, "                                                                            \
  "velocity_x_m_s, velocity_y_m_s, mean_r, mean_g, mean_b, area_px, eccentricity, bbox_x, " \
  "bbox_y, bbox_w, "                                                                        \
  "bbox_h, billboard_w_px, billboard_h_px, px_per_m, anchor_x_px, anchor_y_px, kind, heading_rad"
constexpr const char* kSpriteColumns = "id, " SS_SPRITE_FIELDS;
constexpr const char* kSpriteFields = SS_SPRITE_FIELDS;
constexpr int kSpriteFieldCount = 27;
#undef SS_SPRITE_FIELDS

SpriteRecord ReadSprite(const sql::Stmt& s) {
  SpriteRecord r;
  r.id = s.Int(0);
  r.clip_id = s.Int(1);
  r.camera_id = s.Int(2);
  r.track_id = s.Int(3);
  r.frame = s.Int(4);
  r.timestamp_ns = s.Int(5);
  r.mirrored = s.Int(6) != 0;
  r.mirror_of = s.IsNull(7) ? 0 : s.Int(7);
  r.ground_x_m = s.Real(8);
  r.ground_y_m = s.Real(9);
  r.velocity_x_m_s = s.Real(10);
  r.velocity_y_m_s = s.Real(11);
  r.mean_r = s.Real(12);
  r.mean_g = s.Real(13);
  r.mean_b = s.Real(14);
  r.area_px = s.Real(15);
  r.eccentricity = s.Real(16);
  r.bbox_in_image = cv::Rect(static_cast<int>(s.Int(17)), static_cast<int>(s.Int(18)),
                             static_cast<int>(s.Int(19)), static_cast<int>(s.Int(20)));
  r.billboard_width_px = static_cast<int>(s.Int(21));
  r.billboard_height_px = static_cast<int>(s.Int(22));
  r.px_per_m = s.Real(23);
  r.anchor_x_px = s.Real(24);
  r.anchor_y_px = s.Real(25);
  if (!FromText(s.Text(26), kSpriteKindTexts, r.kind)) {
    throw InputError("sprite " + std::to_string(r.id), "unknown kind '" + s.Text(26) + "'");
  }
  r.heading_rad = s.Real(27);
  return r;
}

ClipRecord ReadClip(const sql::Stmt& s) {
  return {.id = s.Int(0),
          .camera_id = s.Int(1),
          .track_id = s.Int(2),
          .first_frame = s.Int(3),
          .last_frame = s.Int(4),
          .complete = s.Int(5) != 0,
          .complete_seq = s.IsNull(6) ? 0 : s.Int(6)};
}

constexpr const char* kClipColumns =
    "id, camera_id, track_id, first_frame, last_frame, complete, complete_seq";

int64_t FileBytes(const std::string& path) {
  std::error_code ec;
  const auto size = fs::file_size(path, ec);
  return ec ? 0 : static_cast<int64_t>(size);
}

}  // namespace

struct Bank::ReadCache {
  sql::Stmt pixels;
  PixelCodec codec;
};

Bank::Bank(const std::string& path) : Bank(path, Mode::kReadOnly) {}

Bank::Bank(const std::string& path, Mode mode)
    : path_(sql::IsPostgresAddress(path) ? sql::RedactAddress(path) : path),
      db_(std::make_unique<sql::Db>(OpenBankDatabase(path, mode == Mode::kReadWrite))) {}

Bank::~Bank() = default;
Bank::Bank(Bank&&) noexcept = default;
Bank& Bank::operator=(Bank&&) noexcept = default;

Bank::ReadCache& Bank::cache() const {
  if (!cache_) {
    cache_ = std::unique_ptr<ReadCache>(new ReadCache{
        db_->Prepare("SELECT s.mirrored, p.width_px, p.height_px, p.codec, p.data FROM sprites s "
                     "LEFT JOIN sprite_pixels p ON p.sprite_id = coalesce(s.mirror_of, s.id) WHERE "
                     "s.id = ?"),
        {}});
  }
  return *cache_;
}

int Bank::schema_version() const { return ReadSchemaVersion(*db_); }

bool Bank::is_postgres() const { return db_->dialect() == sql::Dialect::kPostgres; }

std::vector<SessionRecord> Bank::ListSessions() const {
  std::vector<SessionRecord> out;
  auto s = db_->Prepare("SELECT id, uid, name, created, source FROM sessions ORDER BY id");
  while (s.Step()) out.push_back({s.Int(0), s.Text(1), s.Text(2), s.Text(3), s.Text(4)});
  return out;
}

std::vector<CameraRecord> Bank::ListCameras() const {
  std::vector<CameraRecord> out;
  auto s = db_->Prepare(
      "SELECT id, session_id, name, cameramodel, width, height FROM cameras ORDER BY id");
  while (s.Step()) {
    out.push_back({s.Int(0), s.Int(1), s.Text(2), s.Text(3), static_cast<int>(s.Int(4)),
                   static_cast<int>(s.Int(5))});
  }
  return out;
}

std::vector<ClipRecord> Bank::ListClips(int64_t completed_after_seq) const {
  std::vector<ClipRecord> out;
  auto s =
      db_->Prepare(std::string("SELECT ") + kClipColumns +
                   " FROM clips WHERE complete = 1 AND complete_seq > ? ORDER BY complete_seq");
  s.Bind(1, completed_after_seq);
  while (s.Step()) out.push_back(ReadClip(s));
  return out;
}

std::vector<ClipRecord> Bank::ListAllClips() const {
  std::vector<ClipRecord> out;
  auto s = db_->Prepare(std::string("SELECT ") + kClipColumns + " FROM clips ORDER BY id");
  while (s.Step()) out.push_back(ReadClip(s));
  return out;
}

std::vector<SpriteFeatures> Bank::LoadFeatures(int64_t completed_after_seq) const {
  std::vector<SpriteFeatures> out;
  out.reserve(static_cast<size_t>(db_->QueryInt(
      "SELECT count(*) FROM sprites s JOIN clips c ON c.id = s.clip_id WHERE c.complete = 1")));
  auto s = db_->Prepare(
      "SELECT s.id, s.clip_id, s.frame, s.timestamp_ns, s.mirror_of, s.mirrored, s.ground_x_m, "
      "s.ground_y_m, "
      "s.velocity_x_m_s, s.velocity_y_m_s, s.mean_r, s.mean_g, s.mean_b, s.area_px, "
      "s.eccentricity, "
      "s.kind, s.heading_rad FROM clips c JOIN sprites s ON s.clip_id = c.id WHERE c.complete = 1 "
      "AND c.complete_seq > ? "
      "ORDER BY s.clip_id, s.mirrored, s.frame");
  s.Bind(1, completed_after_seq);
  while (s.Step()) {
    SpriteFeatures f;
    f.id = s.Int(0);
    f.clip_id = s.Int(1);
    f.frame = s.Int(2);
    f.timestamp_ns = s.Int(3);
    f.mirror_of = s.IsNull(4) ? 0 : s.Int(4);
    f.mirrored = s.Int(5) != 0;
    f.ground_x_m = static_cast<float>(s.Real(6));
    f.ground_y_m = static_cast<float>(s.Real(7));
    f.velocity_x_m_s = static_cast<float>(s.Real(8));
    f.velocity_y_m_s = static_cast<float>(s.Real(9));
    f.mean_r = static_cast<float>(s.Real(10));
    f.mean_g = static_cast<float>(s.Real(11));
    f.mean_b = static_cast<float>(s.Real(12));
    f.area_px = static_cast<float>(s.Real(13));
    f.eccentricity = static_cast<float>(s.Real(14));
    f.floor = s.Text(15) == TextOf(SpriteKind::kFloor, kSpriteKindTexts);
    f.heading_rad = static_cast<float>(s.Real(16));
    if (!out.empty()) {
      SpriteFeatures& before = out.back();
      if (before.clip_id == f.clip_id && before.mirrored == f.mirrored &&
          before.frame + 1 == f.frame) {
        f.prev = static_cast<int32_t>(out.size() - 1);
        before.next = static_cast<int32_t>(out.size());
      }
    }
    out.push_back(f);
  }
  return out;
}

SpriteRecord Bank::LoadSprite(int64_t id) const {
  auto s = db_->Prepare(std::string("SELECT ") + kSpriteColumns + " FROM sprites WHERE id = ?");
  s.Bind(1, id);
  if (!s.Step()) throw InputError(path_, "no sprite with id " + std::to_string(id));
  SpriteRecord r = ReadSprite(s);
  auto tags = db_->Prepare("SELECT tag FROM sprite_tags WHERE sprite_id = ? ORDER BY tag");
  tags.Bind(1, id);
  while (tags.Step()) r.tags.push_back(tags.Text(0));
  return r;
}

SpritePixels Bank::LoadPixels(int64_t id) const {
  ReadCache& c = cache();
  sql::Stmt& s = c.pixels;
  s.Reset();
  s.Bind(1, id);
  if (!s.Step()) throw InputError(path_, "no sprite with id " + std::to_string(id));
  if (s.IsNull(1)) throw WorkError(path_, "sprite " + std::to_string(id) + " has no pixels");
  const bool mirrored = s.Int(0) != 0;
  SpritePixels pixels;
  try {
    pixels = c.codec.Decode(s.Blob(4), s.Bytes(4), static_cast<int>(s.Int(1)),
                            static_cast<int>(s.Int(2)), s.Text(3));
  } catch (const WorkError& e) {
    s.Reset();
    throw WorkError(path_, "sprite " + std::to_string(id) + ": " + e.what());
  }
  s.Reset();
  if (mirrored) {
    cv::flip(pixels.bgra, pixels.bgra, 1);
    cv::flip(pixels.shadow, pixels.shadow, 1);
  }
  return pixels;
}

int64_t Bank::TransitionCount() const { return db_->QueryInt("SELECT count(*) FROM transitions"); }

std::vector<TransitionRecord> Bank::LoadTransitions() const {
  std::vector<TransitionRecord> out;
  out.reserve(static_cast<size_t>(TransitionCount()));
  auto s = db_->Prepare(
      "SELECT from_sprite, to_sprite, d, cost FROM transitions ORDER BY from_sprite, to_sprite");
  while (s.Step()) out.push_back({s.Int(0), s.Int(1), s.Real(2), s.Real(3)});
  return out;
}

namespace {

// The transitions whose `end` column ("from_sprite" or "to_sprite") is `sprite`.
std::vector<TransitionRecord> TransitionsAt(sql::Db& db, const char* end, int64_t sprite) {
  std::vector<TransitionRecord> out;
  auto s =
      db.Prepare(std::string("SELECT from_sprite, to_sprite, d, cost FROM transitions WHERE ") +
                 end + " = ? ORDER BY from_sprite, to_sprite");
  s.Bind(1, sprite);
  while (s.Step()) out.push_back({s.Int(0), s.Int(1), s.Real(2), s.Real(3)});
  return out;
}

}  // namespace

std::vector<TransitionRecord> Bank::LoadTransitionsFrom(int64_t from_sprite) const {
  return TransitionsAt(*db_, "from_sprite", from_sprite);
}

std::vector<TransitionRecord> Bank::LoadTransitionsTo(int64_t to_sprite) const {
  return TransitionsAt(*db_, "to_sprite", to_sprite);
}

std::vector<SpriteRecord> Bank::LoadClipSprites(int64_t clip_id) const {
  std::vector<SpriteRecord> out;
  std::map<int64_t, size_t> at;
  auto s = db_->Prepare(std::string("SELECT ") + kSpriteColumns +
                        " FROM sprites WHERE clip_id = ? AND mirrored = 0 ORDER BY frame");
  s.Bind(1, clip_id);
  while (s.Step()) {
    out.push_back(ReadSprite(s));
    at[out.back().id] = out.size() - 1;
  }
  auto tags = db_->Prepare(
      "SELECT t.sprite_id, t.tag FROM sprite_tags t JOIN sprites s ON s.id = t.sprite_id "
      "WHERE s.clip_id = ? AND s.mirrored = 0 ORDER BY t.tag");
  tags.Bind(1, clip_id);
  while (tags.Step()) {
    const auto it = at.find(tags.Int(0));
    if (it != at.end()) out[it->second].tags.push_back(tags.Text(1));
  }
  return out;
}

std::vector<int64_t> Bank::ClipSpriteIds(int64_t clip_id, int64_t first_frame,
                                         int64_t last_frame) const {
  std::vector<int64_t> out;
  auto s = db_->Prepare(
      "SELECT id FROM sprites WHERE clip_id = ? AND frame BETWEEN ? AND ? ORDER BY frame, "
      "mirrored");
  s.Bind(1, clip_id);
  s.Bind(2, first_frame);
  s.Bind(3, last_frame);
  while (s.Step()) out.push_back(s.Int(0));
  return out;
}

std::map<int64_t, int64_t> Bank::CountClipSprites() const {
  std::map<int64_t, int64_t> out;
  auto s =
      db_->Prepare("SELECT clip_id, count(*) FROM sprites WHERE mirrored = 0 GROUP BY clip_id");
  while (s.Step()) out[s.Int(0)] = s.Int(1);
  return out;
}

std::map<int64_t, std::map<std::string, int64_t>> Bank::CountClipTags() const {
  std::map<int64_t, std::map<std::string, int64_t>> out;
  auto s = db_->Prepare(
      "SELECT s.clip_id, t.tag, count(*) FROM sprite_tags t JOIN sprites s ON s.id = t.sprite_id "
      "WHERE s.mirrored = 0 GROUP BY s.clip_id, t.tag");
  while (s.Step()) out[s.Int(0)][s.Text(1)] = s.Int(2);
  return out;
}

std::vector<int64_t> Bank::SpritesTagged(const std::string& tag) const {
  std::vector<int64_t> out;
  auto s = db_->Prepare("SELECT sprite_id FROM sprite_tags WHERE tag = ? ORDER BY sprite_id");
  s.Bind(1, tag);
  while (s.Step()) out.push_back(s.Int(0));
  return out;
}

std::optional<std::string> Bank::GetMeta(const std::string& key) const {
  auto s = db_->Prepare("SELECT value FROM meta WHERE key = ?");
  s.Bind(1, key);
  if (!s.Step()) return std::nullopt;
  return s.Text(0);
}

std::vector<TransitionLabelRecord> Bank::LoadTransitionLabels() const {
  std::vector<TransitionLabelRecord> out;
  auto s = db_->Prepare(
      "SELECT from_sprite, to_sprite, label, labelled_at, source FROM transition_labels "
      "ORDER BY labelled_at, from_sprite, to_sprite");
  while (s.Step()) out.push_back({s.Int(0), s.Int(1), s.Text(2), s.Text(3), s.Text(4)});
  return out;
}

std::map<std::string, int64_t> Bank::CountTransitionLabels() const {
  std::map<std::string, int64_t> out = {{"yes", 0}, {"no", 0}, {"skip", 0}};
  auto s = db_->Prepare("SELECT label, count(*) FROM transition_labels GROUP BY label");
  while (s.Step()) out[s.Text(0)] = s.Int(1);
  return out;
}

std::vector<double> Bank::BillboardScales() const {
  auto s = db_->Prepare("SELECT DISTINCT px_per_m FROM sprites ORDER BY px_per_m");
  std::vector<double> out;
  while (s.Step()) out.push_back(s.Real(0));
  return out;
}

BankSnapshot::BankSnapshot(const Bank& bank)
    : snapshot_(std::make_unique<sql::ReadSnapshot>(*bank.db_)) {}

BankSnapshot::~BankSnapshot() = default;

BankCounts Bank::Counts() const {
  // One read transaction so that the figures agree with each other.
  BankCounts c;
  {
    sql::ReadSnapshot snapshot(*db_);
    c.schema_version = schema_version();
    c.sessions = db_->QueryInt("SELECT count(*) FROM sessions");
    c.cameras = db_->QueryInt("SELECT count(*) FROM cameras");
    c.clips = db_->QueryInt("SELECT count(*) FROM clips");
    c.clips_complete = db_->QueryInt("SELECT count(*) FROM clips WHERE complete = 1");
    c.sprites = db_->QueryInt("SELECT count(*) FROM sprites");
    c.mirrors = db_->QueryInt("SELECT count(*) FROM sprites WHERE mirrored = 1");
    c.sprites_visible = db_->QueryInt(
        "SELECT count(*) FROM sprites s JOIN clips c ON c.id = s.clip_id WHERE c.complete = 1");
    c.pixel_rows = db_->QueryInt("SELECT count(*) FROM sprite_pixels");
    c.pixel_bytes = db_->QueryInt("SELECT coalesce(sum(length(data)), 0) FROM sprite_pixels");
    c.transitions = TransitionCount();
    c.tags = db_->QueryInt("SELECT count(DISTINCT tag) FROM sprite_tags");
    c.tagged_sprites = db_->QueryInt("SELECT count(DISTINCT sprite_id) FROM sprite_tags");
    if (is_postgres()) {
      // The bank's tables with their indexes and out-of-line (TOAST) data, on the server.
      c.file_bytes = db_->QueryInt(
          "SELECT coalesce(sum(pg_total_relation_size(c.oid)), 0) FROM pg_catalog.pg_class c "
          "JOIN pg_catalog.pg_namespace n ON n.oid = c.relnamespace "
          "WHERE n.nspname = current_schema() AND c.relkind = 'r'");
    }
  }
  if (!is_postgres()) {
    c.file_bytes = FileBytes(path_);
    c.wal_bytes = FileBytes(path_ + "-wal");
  }
  return c;
}

// ---------------------------------------------------------------------------------------------

struct BankWriter::Impl {
  explicit Impl(sql::Db& db)
      : find_clip(
            db.Prepare(std::string("SELECT ") + kClipColumns +
                       " FROM clips WHERE camera_id = ? AND track_id = ? AND first_frame = ?")),
        insert_clip(db.Prepare(
            "INSERT INTO clips (camera_id, track_id, first_frame, last_frame) VALUES (?, ?, ?, ?) "
            "RETURNING id")),
        extend_clip(db.Prepare("UPDATE clips SET last_frame = ? WHERE id = ? AND last_frame < ?")),
        complete_clip(db.Prepare("UPDATE clips SET complete = 1, complete_seq = "
                                 "(SELECT coalesce(max(complete_seq), 0) + 1 FROM clips) "
                                 "WHERE id = ? AND complete = 0")),
        insert_sprite(db.Prepare(
            std::string("INSERT INTO sprites (") + kSpriteFields + ") VALUES " +
            sql::RowPlaceholders(1, kSpriteFieldCount) + " " +
            "ON CONFLICT (camera_id, frame, track_id, mirrored) DO NOTHING RETURNING id")),
        find_sprite(
            db.Prepare("SELECT id FROM sprites WHERE camera_id = ? AND frame = ? AND track_id = ? "
                       "AND mirrored = ?")),
        insert_pixels(
            db.Prepare("INSERT INTO sprite_pixels (sprite_id, width_px, height_px, codec, data) "
                       "VALUES (?, ?, ?, ?, ?) ON CONFLICT (sprite_id) DO UPDATE SET "
                       "width_px = excluded.width_px, height_px = excluded.height_px, "
                       "codec = excluded.codec, data = excluded.data")),
        insert_tag(db.Prepare(
            "INSERT INTO sprite_tags (sprite_id, tag) VALUES (?, ?) ON CONFLICT DO NOTHING")),
        upsert_transition(db.Prepare(
            "INSERT INTO transitions (from_sprite, to_sprite, d, cost) VALUES (?, ?, ?, ?) "
            "ON CONFLICT (from_sprite, to_sprite) DO UPDATE SET "
            "d = excluded.d, cost = excluded.cost")) {}

  sql::Stmt find_clip, insert_clip, extend_clip, complete_clip;
  sql::Stmt insert_sprite, find_sprite, insert_pixels, insert_tag, upsert_transition;
  PixelCodec codec;
};

BankWriter::BankWriter(const std::string& path)
    : Bank(path, Mode::kReadWrite), impl_(std::make_unique<Impl>(db())) {}

BankWriter::~BankWriter() = default;
BankWriter::BankWriter(BankWriter&&) noexcept = default;
BankWriter& BankWriter::operator=(BankWriter&&) noexcept = default;

int64_t BankWriter::AddSession(const SessionRecord& session) {
  if (session.uid.empty()) throw WorkError(path(), "a session needs a non-empty uid");
  sql::Transaction tx(db());
  auto insert = db().Prepare(
      "INSERT INTO sessions (uid, name, created, source) VALUES (?, ?, ?, ?) ON CONFLICT (uid) DO "
      "NOTHING");
  insert.Bind(1, session.uid)
      .Bind(2, session.name)
      .Bind(3, session.created)
      .Bind(4, session.source)
      .Step();
  auto find = db().Prepare("SELECT id FROM sessions WHERE uid = ?");
  find.Bind(1, session.uid).Step();
  const int64_t id = find.Int(0);
  find.Reset();
  tx.Commit();
  return id;
}

void BankWriter::RenameSession(int64_t session_id, const std::string& name) {
  sql::Transaction tx(db());
  auto update = db().Prepare("UPDATE sessions SET name = ? WHERE id = ?");
  update.Bind(1, name).Bind(2, session_id).Step();
  update.Reset();
  auto find = db().Prepare("SELECT 1 FROM sessions WHERE id = ?");
  if (!find.Bind(1, session_id).Step()) {
    throw WorkError(path(), "no session with id " + std::to_string(session_id) + " to rename");
  }
  find.Reset();
  tx.Commit();
}

int64_t BankWriter::AddCamera(int64_t session_id, const CameraRecord& camera) {
  if (camera.name.empty()) throw WorkError(path(), "a camera needs a non-empty name");
  sql::Transaction tx(db());
  auto session = db().Prepare("SELECT 1 FROM sessions WHERE id = ?");
  if (!session.Bind(1, session_id).Step()) {
    throw WorkError(
        path(), "camera '" + camera.name + "': no session with id " + std::to_string(session_id));
  }
  session.Reset();
  auto insert = db().Prepare(
      "INSERT INTO cameras (session_id, name, cameramodel, width, height) VALUES (?, ?, ?, ?, ?) "
      "ON CONFLICT (session_id, name) DO NOTHING");
  insert.Bind(1, session_id)
      .Bind(2, camera.name)
      .Bind(3, camera.cameramodel)
      .Bind(4, static_cast<int64_t>(camera.width))
      .Bind(5, static_cast<int64_t>(camera.height))
      .Step();
  auto find = db().Prepare("SELECT id FROM cameras WHERE session_id = ? AND name = ?");
  find.Bind(1, session_id).Bind(2, camera.name).Step();
  const int64_t id = find.Int(0);
  find.Reset();
  tx.Commit();
  return id;
}

AppendResult BankWriter::AppendClipBatch(const ClipRecord& clip,
                                         const std::vector<SpriteRecord>& sprites) {
  const std::string where = path() + ": clip (camera " + std::to_string(clip.camera_id) +
                            ", track " + std::to_string(clip.track_id) + ", first frame " +
                            std::to_string(clip.first_frame) + ")";
  int64_t last_frame = std::max(clip.first_frame, clip.last_frame);
  for (const SpriteRecord& s : sprites) {
    const std::string who =
        where + ", frame " + std::to_string(s.frame) + (s.mirrored ? " (mirrored)" : "");
    if (s.frame < clip.first_frame) throw WorkError(who, "sprite is before the clip's first frame");
    if (s.billboard_width_px <= 0 || s.billboard_height_px <= 0 || !(s.px_per_m > 0)) {
      throw WorkError(who, "billboard size and px_per_m must be positive");
    }
    if (!s.mirrored && (s.pixels.bgra.cols != s.billboard_width_px ||
                        s.pixels.bgra.rows != s.billboard_height_px)) {
      throw WorkError(who, "an original sprite needs billboard pixels of its billboard size (" +
                               std::to_string(s.billboard_width_px) + "x" +
                               std::to_string(s.billboard_height_px) + ", got " +
                               std::to_string(s.pixels.bgra.cols) + "x" +
                               std::to_string(s.pixels.bgra.rows) + ")");
    }
    last_frame = std::max(last_frame, s.frame);
  }

  Impl& w = *impl_;
  sql::Transaction tx(db());
  AppendResult result;
  w.find_clip.Reset();
  w.find_clip.Bind(1, clip.camera_id).Bind(2, clip.track_id).Bind(3, clip.first_frame);
  if (w.find_clip.Step()) {
    const ClipRecord stored = ReadClip(w.find_clip);
    w.find_clip.Reset();
    result.clip_id = stored.id;
    if (stored.complete && last_frame > stored.last_frame) {
      throw WorkError(where, "the clip is complete up to frame " +
                                 std::to_string(stored.last_frame) + "; a batch reaches frame " +
                                 std::to_string(last_frame));
    }
    w.extend_clip.Reset();
    w.extend_clip.Bind(1, last_frame).Bind(2, stored.id).Bind(3, last_frame).Step();
  } else {
    w.find_clip.Reset();
    auto camera = db().Prepare("SELECT 1 FROM cameras WHERE id = ?");
    if (!camera.Bind(1, clip.camera_id).Step()) throw WorkError(where, "no camera with that id");
    camera.Reset();
    w.insert_clip.Reset();
    w.insert_clip.Bind(1, clip.camera_id)
        .Bind(2, clip.track_id)
        .Bind(3, clip.first_frame)
        .Bind(4, last_frame)
        .Step();
    result.clip_id = w.insert_clip.Int(0);
    w.insert_clip.Reset();
  }

  if (db().dialect() == sql::Dialect::kPostgres) {
    AppendSpritesManyRows(clip, result.clip_id, sprites, where, &result);
  } else {
    AppendSpritesOneByOne(clip, result.clip_id, sprites, where, &result);
  }
  if (clip.complete) {
    SerializeClipCompletion(db());
    w.complete_clip.Reset();
    w.complete_clip.Bind(1, result.clip_id).Step();
  }
  tx.Commit();
  return result;
}

namespace {

// Binds one sprite's columns (kSpriteFields' order) from `first`; returns the next index.
int BindSprite(sql::Stmt& q, int first, int64_t clip_id, const ClipRecord& clip,
               const SpriteRecord& s, int64_t mirror_of) {
  const double reals[] = {s.ground_x_m, s.ground_y_m, s.velocity_x_m_s, s.velocity_y_m_s, s.mean_r,
                          s.mean_g,     s.mean_b,     s.area_px,        s.eccentricity};
  const int64_t box[] = {s.bbox_in_image.x,      s.bbox_in_image.y,    s.bbox_in_image.width,
                         s.bbox_in_image.height, s.billboard_width_px, s.billboard_height_px};
  int i = first;
  for (int64_t v :
       {clip_id, clip.camera_id, clip.track_id, s.frame, s.timestamp_ns, int64_t{s.mirrored}}) {
    q.Bind(i++, v);
  }
  if (s.mirrored) {
    q.Bind(i++, mirror_of);
  } else {
    q.BindNull(i++);
  }
  for (double v : reals) q.Bind(i++, v);
  for (int64_t v : box) q.Bind(i++, v);
  for (double v : {s.px_per_m, s.anchor_x_px, s.anchor_y_px}) q.Bind(i++, v);
  q.Bind(i++, std::string(TextOf(s.kind, kSpriteKindTexts)));
  q.Bind(i++, s.heading_rad);
  return i;
}

}  // namespace

void BankWriter::AppendSpritesOneByOne(const ClipRecord& clip, int64_t clip_id,
                                       const std::vector<SpriteRecord>& sprites,
                                       const std::string& where, AppendResult* out) {
  Impl& w = *impl_;
  AppendResult& result = *out;
  result.clip_id = clip_id;
  result.sprite_ids.assign(sprites.size(), 0);
  auto find = [&](int64_t frame, bool mirrored) -> int64_t {
    w.find_sprite.Reset();
    w.find_sprite.Bind(1, clip.camera_id)
        .Bind(2, frame)
        .Bind(3, clip.track_id)
        .Bind(4, int64_t{mirrored});
    const int64_t id = w.find_sprite.Step() ? w.find_sprite.Int(0) : 0;
    w.find_sprite.Reset();
    return id;
  };
  // Originals first, so that mirrors in the same batch find them.
  for (int pass = 0; pass < 2; ++pass) {
    for (size_t i = 0; i < sprites.size(); ++i) {
      const SpriteRecord& s = sprites[i];
      if (s.mirrored != (pass == 1)) continue;
      int64_t mirror_of = 0;
      if (s.mirrored) {
        mirror_of = find(s.frame, false);
        if (mirror_of == 0) {
          throw WorkError(where + ", frame " + std::to_string(s.frame),
                          "a mirrored sprite needs its original (same camera, track and frame) in "
                          "the bank or batch");
        }
      }
      sql::Stmt& q = w.insert_sprite;
      q.Reset();
      BindSprite(q, 1, result.clip_id, clip, s, mirror_of);
      int64_t id = 0;
      if (q.Step()) {  // inserted: RETURNING gave its id (a sprite already stored returns no row)
        id = q.Int(0);
        q.Reset();
        ++result.inserted;
        if (!s.mirrored) {
          std::vector<uint8_t> const* blob = nullptr;
          try {
            blob = &w.codec.Encode(s.pixels);
          } catch (const WorkError& e) {
            throw WorkError(where + ", frame " + std::to_string(s.frame), e.what());
          }
          w.insert_pixels.Reset();
          w.insert_pixels.Bind(1, id)
              .Bind(2, int64_t{s.pixels.bgra.cols})
              .Bind(3, int64_t{s.pixels.bgra.rows});
          w.insert_pixels.Bind(4, std::string_view(kPixelCodec))
              .BindBlob(5, blob->data(), blob->size())
              .Step();
        }
      } else {
        id = find(s.frame, s.mirrored);
      }
      result.sprite_ids[i] = id;
      for (const std::string& tag : s.tags) {
        w.insert_tag.Reset();
        w.insert_tag.Bind(1, id).Bind(2, tag).Step();
      }
    }
  }
}

// A server a network hop away answers each statement in a round trip: the batch's sprites go
// in a few statements of many rows each (originals, their pixels, mirrors), not one per sprite.
void BankWriter::AppendSpritesManyRows(const ClipRecord& clip, int64_t clip_id,
                                       const std::vector<SpriteRecord>& sprites,
                                       const std::string& where, AppendResult* out) {
  constexpr int kColumns = kSpriteFieldCount, kRowsPerStatement = 200;
  Impl& w = *impl_;
  AppendResult& result = *out;
  result.clip_id = clip_id;
  result.sprite_ids.assign(sprites.size(), 0);
  // The ids of this clip's sprites already stored (before this batch), by (frame, mirrored).
  std::map<std::pair<int64_t, bool>, int64_t> ids;
  if (!sprites.empty()) {
    int64_t lo = sprites.front().frame, hi = lo;
    for (const SpriteRecord& s : sprites) lo = std::min(lo, s.frame), hi = std::max(hi, s.frame);
    auto q = db().Prepare(
        "SELECT id, frame, mirrored FROM sprites WHERE camera_id = ? AND track_id = ? "
        "AND frame BETWEEN ? AND ?");
    q.Bind(1, clip.camera_id).Bind(2, clip.track_id).Bind(3, lo).Bind(4, hi);
    while (q.Step()) ids[{q.Int(1), q.Int(2) != 0}] = q.Int(0);
  }
  for (int pass = 0; pass < 2; ++pass) {
    const bool mirrors = pass == 1;
    std::vector<size_t> fresh;  // batch positions of the sprites to insert
    for (size_t i = 0; i < sprites.size(); ++i) {
      const SpriteRecord& s = sprites[i];
      if (s.mirrored != mirrors) continue;
      if (ids.count({s.frame, s.mirrored})) continue;
      if (mirrors && !ids.count({s.frame, false})) {
        throw WorkError(where + ", frame " + std::to_string(s.frame),
                        "a mirrored sprite needs its original (same camera, track and frame) in "
                        "the bank or batch");
      }
      fresh.push_back(i);
    }
    for (size_t at = 0; at < fresh.size(); at += kRowsPerStatement) {
      const size_t n = std::min<size_t>(kRowsPerStatement, fresh.size() - at);
      auto q = db().Prepare(
          std::string("INSERT INTO sprites (") + kSpriteFields + ") VALUES " +
          sql::RowPlaceholders(static_cast<int>(n), kColumns) +
          " ON CONFLICT (camera_id, frame, track_id, mirrored) DO NOTHING RETURNING id, frame");
      int index = 1;
      for (size_t k = 0; k < n; ++k) {
        const SpriteRecord& s = sprites[fresh[at + k]];
        index = BindSprite(q, index, clip_id, clip, s, mirrors ? ids.at({s.frame, false}) : 0);
      }
      std::vector<std::pair<int64_t, int64_t>> inserted;  // (frame, id)
      while (q.Step()) inserted.emplace_back(q.Int(1), q.Int(0));
      result.inserted += static_cast<int64_t>(inserted.size());
      for (const auto& [frame, id] : inserted) ids[{frame, mirrors}] = id;
      if (!mirrors && !inserted.empty()) {
        auto p = db().Prepare(
            "INSERT INTO sprite_pixels (sprite_id, width_px, height_px, codec, data) VALUES " +
            sql::RowPlaceholders(static_cast<int>(inserted.size()), 5) +
            " ON CONFLICT (sprite_id) DO UPDATE SET width_px = excluded.width_px, "
            "height_px = excluded.height_px, codec = excluded.codec, data = excluded.data");
        std::map<int64_t, const SpriteRecord*> by_frame;
        for (size_t k = 0; k < n; ++k)
          by_frame[sprites[fresh[at + k]].frame] = &sprites[fresh[at + k]];
        int pi = 1;
        for (const auto& [frame, id] : inserted) {
          const SpriteRecord& s = *by_frame.at(frame);
          const std::vector<uint8_t>* blob = nullptr;
          try {
            blob = &w.codec.Encode(s.pixels);
          } catch (const WorkError& e) {
            throw WorkError(where + ", frame " + std::to_string(s.frame), e.what());
          }
          p.Bind(pi, id)
              .Bind(pi + 1, int64_t{s.pixels.bgra.cols})
              .Bind(pi + 2, int64_t{s.pixels.bgra.rows});
          p.Bind(pi + 3, std::string_view(kPixelCodec))
              .BindBlob(pi + 4, blob->data(), blob->size());
          pi += 5;
        }
        p.Step();
      }
    }
    if (!fresh.empty() && std::any_of(fresh.begin(), fresh.end(), [&](size_t i) {
          return !ids.count({sprites[i].frame, mirrors});
        })) {
      // Another writer stored some of them meanwhile (ON CONFLICT skipped them): read their ids.
      auto q = db().Prepare(
          "SELECT id, frame FROM sprites WHERE camera_id = ? AND track_id = ? AND mirrored = ?");
      q.Bind(1, clip.camera_id).Bind(2, clip.track_id).Bind(3, int64_t{mirrors});
      while (q.Step()) ids.try_emplace({q.Int(1), mirrors}, q.Int(0));
    }
  }
  for (size_t i = 0; i < sprites.size(); ++i) {
    const SpriteRecord& s = sprites[i];
    const int64_t id = ids.at({s.frame, s.mirrored});
    result.sprite_ids[i] = id;
    for (const std::string& tag : s.tags) {
      w.insert_tag.Reset();
      w.insert_tag.Bind(1, id).Bind(2, tag).Step();
    }
  }
}

void BankWriter::UpsertTransitions(const std::vector<TransitionRecord>& transitions) {
  sql::Transaction tx(db());
  if (is_postgres()) {
    // A round trip a row cost ~0.15 ms on a server (a worker's whole unit stored 5x slower than
    // it was found): rows go 1,000 a statement. One statement may not touch a row twice, so a
    // pair given twice keeps its last values, as one statement a row would.
    constexpr size_t kRows = 1000;
    std::vector<TransitionRecord> chunk;
    std::map<std::pair<int64_t, int64_t>, size_t> at;
    for (size_t first = 0; first < transitions.size(); first += kRows) {
      chunk.clear();
      at.clear();
      for (size_t k = first; k < std::min(transitions.size(), first + kRows); ++k) {
        const TransitionRecord& t = transitions[k];
        const auto [it, fresh] = at.try_emplace({t.from_sprite, t.to_sprite}, chunk.size());
        if (fresh)
          chunk.push_back(t);
        else
          chunk[it->second] = t;
      }
      sql::Stmt q =
          db().Prepare("INSERT INTO transitions (from_sprite, to_sprite, d, cost) VALUES " +
                       sql::RowPlaceholders(static_cast<int>(chunk.size()), 4) +
                       " ON CONFLICT (from_sprite, to_sprite) DO UPDATE SET d = excluded.d, cost = "
                       "excluded.cost");
      for (size_t r = 0; r < chunk.size(); ++r) {
        const int i = static_cast<int>(4 * r);
        q.Bind(i + 1, chunk[r].from_sprite)
            .Bind(i + 2, chunk[r].to_sprite)
            .Bind(i + 3, chunk[r].d)
            .Bind(i + 4, chunk[r].cost);
      }
      q.Step();
    }
    tx.Commit();
    return;
  }
  sql::Stmt& q = impl_->upsert_transition;
  for (const TransitionRecord& t : transitions) {
    q.Reset();
    q.Bind(1, t.from_sprite).Bind(2, t.to_sprite).Bind(3, t.d).Bind(4, t.cost).Step();
  }
  tx.Commit();
}

void BankWriter::ClearTransitions() { db().Exec("DELETE FROM transitions"); }

int64_t BankWriter::PruneTransitions(std::span<const int64_t> from_sprites, int keep,
                                     std::vector<TransitionRecord>* bars) {
  if (keep < 1) throw WorkError(path(), "PruneTransitions keeps at least 1 transition a sprite");
  if (bars) bars->clear();
  int64_t removed = 0;
  sql::Transaction tx(db());
  // The rank of every transition out of the named sprites, by (cost, to_sprite). One statement
  // for the deletion: whichever of two concurrent writers prunes last sees both their rows, so
  // the table ends as the K cheapest of all (SQLite 3.25+ and PostgreSQL have the window).
  constexpr size_t kSprites = 500;
  for (size_t first = 0; first < from_sprites.size(); first += kSprites) {
    const size_t count = std::min(from_sprites.size() - first, kSprites);
    const std::string ranked =
        "SELECT from_sprite, to_sprite, d, cost, ROW_NUMBER() OVER (PARTITION BY from_sprite "
        "ORDER BY cost, to_sprite) AS r FROM transitions WHERE from_sprite IN " +
        sql::RowPlaceholders(1, static_cast<int>(count));
    sql::Stmt del = db().Prepare(
        "DELETE FROM transitions WHERE (from_sprite, to_sprite) IN (SELECT from_sprite, "
        "to_sprite FROM (" +
        ranked + ") AS ranked WHERE r > ?)");
    for (size_t k = 0; k < count; ++k) del.Bind(static_cast<int>(k) + 1, from_sprites[first + k]);
    del.Bind(static_cast<int>(count) + 1, int64_t{keep});
    del.Step();
    removed += del.Changes();
    if (!bars) continue;
    sql::Stmt bar = db().Prepare("SELECT from_sprite, to_sprite, d, cost FROM (" + ranked +
                                 ") AS ranked WHERE r = ?");
    for (size_t k = 0; k < count; ++k) bar.Bind(static_cast<int>(k) + 1, from_sprites[first + k]);
    bar.Bind(static_cast<int>(count) + 1, int64_t{keep});
    while (bar.Step()) bars->push_back({bar.Int(0), bar.Int(1), bar.Real(2), bar.Real(3)});
  }
  tx.Commit();
  return removed;
}

void BankWriter::Tag(const std::vector<int64_t>& sprite_ids, const std::string& tag) {
  if (tag.empty()) throw InputError(path(), "a tag must not be empty");
  sql::Transaction tx(db());
  auto exists = db().Prepare("SELECT 1 FROM sprites WHERE id = ?");
  for (int64_t id : sprite_ids) {
    exists.Reset();
    if (!exists.Bind(1, id).Step())
      throw InputError(path(), "no sprite with id " + std::to_string(id));
    impl_->insert_tag.Reset();
    impl_->insert_tag.Bind(1, id).Bind(2, tag).Step();
  }
  exists.Reset();
  tx.Commit();
}

void BankWriter::Untag(const std::vector<int64_t>& sprite_ids, const std::string& tag) {
  sql::Transaction tx(db());
  auto remove = db().Prepare("DELETE FROM sprite_tags WHERE sprite_id = ? AND tag = ?");
  for (int64_t id : sprite_ids) {
    remove.Reset();
    remove.Bind(1, id).Bind(2, tag).Step();
  }
  tx.Commit();
}

void BankWriter::SetMeta(const std::string& key, const std::string& value) {
  if (key == "schema_version" || key == "application")
    throw WorkError(path(), "meta key '" + key + "' is reserved");
  auto q = db().Prepare(
      "INSERT INTO meta (key, value) VALUES (?, ?) ON CONFLICT (key) DO UPDATE SET value = "
      "excluded.value");
  q.Bind(1, key).Bind(2, value).Step();
}

std::string BankWriter::KeepMeta(const std::string& key, const std::string& value) {
  if (key == "schema_version" || key == "application")
    throw WorkError(path(), "meta key '" + key + "' is reserved");
  // One statement each: on PostgreSQL two writers inserting at once are ordered by the key's
  // unique index (the second does nothing), and both then read the first one's value.
  db().Prepare("INSERT INTO meta (key, value) VALUES (?, ?) ON CONFLICT (key) DO NOTHING")
      .Bind(1, key)
      .Bind(2, value)
      .Step();
  const std::optional<std::string> kept = GetMeta(key);
  if (!kept) throw WorkError(path(), "meta key '" + key + "' vanished after it was set");
  return *kept;
}

void BankWriter::SetTransitionLabel(const TransitionLabelRecord& label) {
  if (label.label != "yes" && label.label != "no" && label.label != "skip") {
    throw InputError("label", "expected yes, no or skip, got \"" + label.label + "\"");
  }
  if (label.from_sprite == label.to_sprite) {
    throw InputError("label",
                     "sprite " + std::to_string(label.from_sprite) + " paired with itself");
  }
  sql::Transaction tx(db());
  auto exists = db().Prepare("SELECT 1 FROM sprites WHERE id = ?");
  for (int64_t id : {label.from_sprite, label.to_sprite}) {
    exists.Reset();
    if (!exists.Bind(1, id).Step())
      throw InputError(path(), "no sprite with id " + std::to_string(id));
  }
  exists.Reset();
  auto q = db().Prepare(
      "INSERT INTO transition_labels (from_sprite, to_sprite, label, labelled_at, source) VALUES "
      "(?, ?, ?, ?, ?) "
      "ON CONFLICT (from_sprite, to_sprite) DO UPDATE SET label = excluded.label, "
      "labelled_at = excluded.labelled_at, source = excluded.source");
  q.Bind(1, label.from_sprite)
      .Bind(2, label.to_sprite)
      .Bind(3, label.label)
      .Bind(4, label.labelled_at);
  q.Bind(5, label.source).Step();
  q.Reset();
  tx.Commit();
}

bool BankWriter::RemoveTransitionLabel(int64_t from_sprite, int64_t to_sprite) {
  auto q = db().Prepare("DELETE FROM transition_labels WHERE from_sprite = ? AND to_sprite = ?");
  q.Bind(1, from_sprite).Bind(2, to_sprite).Step();
  return q.Changes() > 0;
}

}  // namespace ss
