#include "core/camera_model.h"

#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <optional>
#include <regex>
#include <sstream>
#include <stdexcept>
#include <system_error>
#include <utility>

#include "core/error.h"
#include "core/posix.h"
#include "core/replace_file.h"

// libmrcal's headers are plain C without extern "C" guards.
extern "C" {
#include <mrcal/mrcal.h>
}

namespace ss {

struct MrcalLens {
  mrcal_lensmodel_t model;
  bool can_project_behind_camera = false;
  int num_params = 0;
};

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

static_assert(sizeof(mrcal_point3_t) == sizeof(Eigen::Vector3d),
              "mrcal_point3_t must be 3 doubles");
static_assert(sizeof(mrcal_point2_t) == sizeof(Eigen::Vector2d),
              "mrcal_point2_t must be 2 doubles");

struct MrcalModelDeleter {
  void operator()(mrcal_cameramodel_t* m) const { mrcal_free_cameramodel(&m); }
};
using MrcalModelPtr = std::unique_ptr<mrcal_cameramodel_t, MrcalModelDeleter>;

// Parses a lens model name; nullptr when mrcal does not know it.
std::shared_ptr<const MrcalLens> ParseLens(const std::string& name) {
  auto lens = std::make_shared<MrcalLens>();
  if (!mrcal_lensmodel_from_name(&lens->model, name.c_str())) return nullptr;
  lens->num_params = mrcal_lensmodel_num_params(&lens->model);
  lens->can_project_behind_camera =
      mrcal_lensmodel_metadata(&lens->model).can_project_behind_camera;
  return lens;
}

std::string LensName(const mrcal_lensmodel_t& model) {
  char buf[256];
  if (!mrcal_lensmodel_name(buf, sizeof buf, &model))
    throw std::logic_error("mrcal_lensmodel_name failed");
  return buf;
}

// Shortest text that reads back as exactly the same double.
std::string ExactNumber(double v) {
  char buf[64];
  const auto res = std::to_chars(buf, buf + sizeof buf, v);
  return std::string(buf, res.ptr);
}

// The keys of a .cameramodel with comments removed, for error messages only.
std::string StripComments(const std::string& text) {
  std::string out;
  char quote = 0;
  for (size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (quote) {
      if (c == quote) quote = 0;
    } else if (c == '\'' || c == '"') {
      quote = c;
    } else if (c == '#') {
      while (i < text.size() && text[i] != '\n') ++i;
      out += '\n';
      continue;
    }
    out += c;
  }
  return out;
}

// Why mrcal refused `text`, as precisely as we can tell (mrcal itself only
// prints its reason to stderr).
std::string DiagnoseRefusal(const std::string& text) {
  const std::string s = StripComments(text);
  if (s.find('{') == std::string::npos) return "not a .cameramodel (no '{ ... }' dictionary)";
  auto key_value = [&](const std::string& key) -> std::optional<std::smatch> {
    static const std::string kQuote = "['\"]";
    const std::regex re(kQuote + key + kQuote + R"(\s*:\s*)");
    std::smatch m;
    if (!std::regex_search(s, m, re)) return std::nullopt;
    return m;
  };
  // The items of the list that follows a key; nullopt when it is not a flat list.
  auto list_items = [&](const std::smatch& m) -> std::optional<std::vector<std::string>> {
    const size_t start = static_cast<size_t>(m.position(0) + m.length(0));
    if (start >= s.size() || (s[start] != '[' && s[start] != '(')) return std::nullopt;
    const size_t end = s.find_first_of("])", start);
    if (end == std::string::npos) return std::nullopt;
    std::vector<std::string> items;
    std::stringstream list(s.substr(start + 1, end - start - 1));
    for (std::string item; std::getline(list, item, ',');) {
      const size_t b = item.find_first_not_of(" \t\r\n");
      if (b != std::string::npos)
        items.push_back(item.substr(b, item.find_last_not_of(" \t\r\n") - b + 1));
    }
    return items;
  };
  auto list_count = [&](const std::smatch& m) -> int {
    const auto items = list_items(m);
    return items ? static_cast<int>(items->size()) : -1;
  };
  for (const char* key : {"lensmodel", "intrinsics", "extrinsics", "imagersize"}) {
    if (!key_value(key)) return std::string("missing key '") + key + "'";
  }
  const auto lens_kv = key_value("lensmodel");
  const size_t name_start = static_cast<size_t>(lens_kv->position(0) + lens_kv->length(0));
  std::string name;
  if (name_start < s.size() && (s[name_start] == '\'' || s[name_start] == '"')) {
    const size_t name_end = s.find(s[name_start], name_start + 1);
    if (name_end != std::string::npos) name = s.substr(name_start + 1, name_end - name_start - 1);
  }
  const auto lens = ParseLens(name);
  if (!lens) return "unknown lens model '" + name + "'";
  const int have = list_count(*key_value("intrinsics"));
  if (have >= 0 && have != lens->num_params) {
    return name + " needs " + std::to_string(lens->num_params) + " intrinsics, the file has " +
           std::to_string(have);
  }
  const int extrinsics = list_count(*key_value("extrinsics"));
  if (extrinsics >= 0 && extrinsics != 6) {
    return "'extrinsics' needs 6 values (rt_cam_ref), the file has " + std::to_string(extrinsics);
  }
  const auto imager = list_items(*key_value("imagersize"));
  if (imager && imager->size() != 2) {
    return "'imagersize' needs 2 values, the file has " + std::to_string(imager->size());
  }
  if (imager && (std::atof((*imager)[0].c_str()) <= 0 || std::atof((*imager)[1].c_str()) <= 0)) {
    return "imager size " + (*imager)[0] + "x" + (*imager)[1] + " is not positive";
  }
  return "mrcal could not parse it as a .cameramodel (its reason is on stderr)";
}

}  // namespace

CameraModel::CameraModel(const std::string& lensmodel, std::vector<double> intrinsics, int width,
                         int height, Rigid3 cam_from_ground)
    : intrinsics_(std::move(intrinsics)),
      width_(width),
      height_(height),
      cam_from_ground_(std::move(cam_from_ground)) {
  lens_ = ParseLens(lensmodel);
  if (!lens_) throw InputError("camera model", "unknown lens model '" + lensmodel + "'");
  lensmodel_ = LensName(lens_->model);
  if (static_cast<int>(intrinsics_.size()) != lens_->num_params) {
    throw InputError("camera model", lensmodel_ + " needs " + std::to_string(lens_->num_params) +
                                         " intrinsics, got " + std::to_string(intrinsics_.size()));
  }
  for (size_t i = 0; i < intrinsics_.size(); ++i) {
    if (!std::isfinite(intrinsics_[i])) {
      throw InputError("camera model", "intrinsics[" + std::to_string(i) + "] is not finite");
    }
  }
  if (width_ <= 0 || height_ <= 0) {
    throw InputError("camera model", "imager size " + std::to_string(width_) + "x" +
                                         std::to_string(height_) + " is not positive");
  }
  if (!cam_from_ground_.rotation.allFinite() || !cam_from_ground_.translation.allFinite()) {
    throw InputError("camera model", "cam_from_ground is not finite");
  }
}

namespace {

// mrcal's parser (libmrcal 2.x) reads past the end of the text when a quoted string is not
// closed ("{ 'abc", or a backslash as the last character of a string; found by tests/fuzz):
// such a text, e.g. a model file cut short, is refused here, naming the line the string starts on.
void CheckStringsClosed(const std::string& text, const std::string& origin) {
  int line = 1;
  for (size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (c == '\n') {
      ++line;
    } else if (c == '#') {  // a comment, to the end of its line
      while (i + 1 < text.size() && text[i + 1] != '\n') ++i;
    } else if (c == '\'' || c == '"') {
      const int start = line;
      bool closed = false;
      for (++i; i < text.size(); ++i) {
        if (text[i] == '\n') ++line;
        if (text[i] == '\\') {
          ++i;  // an escaped character, whatever it is
          if (i < text.size() && text[i] == '\n') ++line;
        } else if (text[i] == c) {
          closed = true;
          break;
        }
      }
      if (!closed) {
        throw InputError(origin, "a quoted string at line " + std::to_string(start) +
                                     " is not closed (is the file cut short?)");
      }
    }
  }
}

}  // namespace

CameraModel CameraModel::Parse(const std::string& text, const std::string& origin) {
  if (text.find_first_not_of(" \t\r\n") == std::string::npos)
    throw InputError(origin, "empty camera model");
  if (text.size() > static_cast<size_t>(std::numeric_limits<int>::max())) {
    throw InputError(origin, "too large to be a camera model");
  }
  CheckStringsClosed(text, origin);
  // mrcal's parser (libmrcal 2.x) reads past the end of a text whose last line is a comment
  // without its newline (found by tests/fuzz: "# " crashes it): end every text with one.
  std::string terminated = text;
  if (terminated.back() != '\n') terminated.push_back('\n');
  MrcalModelPtr m(
      mrcal_read_cameramodel_string(terminated.data(), static_cast<int>(terminated.size())));
  if (!m) throw InputError(origin, DiagnoseRefusal(text));
  for (double v : m->rt_cam_ref) {
    if (!std::isfinite(v))
      throw InputError(origin, "'extrinsics' holds a value that is not finite");
  }
  const int n = mrcal_lensmodel_num_params(&m->lensmodel);
  std::vector<double> intrinsics(m->intrinsics, m->intrinsics + n);
  // Every mrcal lens model starts with the pinhole core fx, fy, cx, cy. A file whose focal
  // length is 0 (or less) projects every point to the centre: nothing it sees could be keyed
  // or grounded. (A solver may still make such a model, to report it untrusted.)
  if (n >= 2 && !(intrinsics[0] > 0 && intrinsics[1] > 0)) {
    throw InputError(origin, "focal lengths fx = " + std::to_string(intrinsics[0]) +
                                 ", fy = " + std::to_string(intrinsics[1]) +
                                 " (intrinsics[0], [1]) must be positive numbers of pixels");
  }
  try {
    CameraModel model(LensName(m->lensmodel), std::move(intrinsics),
                      static_cast<int>(m->imagersize[0]), static_cast<int>(m->imagersize[1]),
                      Rigid3::FromRt(m->rt_cam_ref));
    model.rt_as_read_.emplace();
    std::copy(m->rt_cam_ref, m->rt_cam_ref + 6, model.rt_as_read_->begin());
    return model;
  } catch (const InputError& e) {
    // Re-name the error after the file: "camera model: X" -> "ORIGIN: X".
    std::string reason = e.what();
    const std::string prefix = "camera model: ";
    if (reason.rfind(prefix, 0) == 0) reason = reason.substr(prefix.size());
    throw InputError(origin, reason);
  }
}

CameraModel CameraModel::Read(const std::string& path) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec))
    throw InputError(path, "is a directory, not a camera model");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path, std::string("cannot open camera model: ") + ErrnoText(errno));
  std::ostringstream text;
  text << in.rdbuf();
  if (in.bad()) throw InputError(path, "cannot read camera model");
  return Parse(text.str(), path);
}

std::string CameraModel::ToText() const {
  if (!valid()) throw std::logic_error("CameraModel::ToText on an empty model");
  double rt[6];
  cam_from_ground_.ToRt(rt);
  if (rt_as_read_) std::copy(rt_as_read_->begin(), rt_as_read_->end(), rt);
  std::string out;
  out += "# SpriteStation camera model (mrcal .cameramodel). The reference frame is the\n";
  out += "# ground: z up, z = 0 the floor, metres. extrinsics = rt_cam_ref = cam_from_ground.\n";
  out += "{\n";
  out += "    'lensmodel':  '" + lensmodel_ + "',\n\n";
  out += "    # intrinsics are fx,fy,cx,cy,distortion0,distortion1,....\n";
  out += "    'intrinsics': [";
  for (double v : intrinsics_) out += " " + ExactNumber(v) + ",";
  out += "],\n\n";
  out += "    # extrinsics are rt_fromref\n";
  out += "    'extrinsics': [";
  for (double v : rt) out += " " + ExactNumber(v) + ",";
  out += "],\n\n";
  out += "    'imagersize': [ " + std::to_string(width_) + ", " + std::to_string(height_) + ",],\n";
  out += "}\n";
  return out;
}

void CameraModel::Write(const std::string& path) const {
  for (double v : intrinsics_) {
    if (!std::isfinite(v)) throw WorkError(path, "camera model has a non-finite intrinsic");
  }
  const std::string text = ToText();
  ReplaceFile(path, text, "camera model");
}

Eigen::Vector3d CameraModel::CentreInGround() const {
  return -(cam_from_ground_.rotation.transpose() * cam_from_ground_.translation);
}

void CameraModel::ProjectMany(const Eigen::Vector3d* points_in_cam, size_t n,
                              Eigen::Vector2d* pixels) const {
  if (!valid()) throw std::logic_error("CameraModel::Project on an empty model");
  if (n == 0) return;
  const auto* p = reinterpret_cast<const mrcal_point3_t*>(points_in_cam);
  auto* q = reinterpret_cast<mrcal_point2_t*>(pixels);
  if (!mrcal_project(q, nullptr, nullptr, p, static_cast<int>(n), &lens_->model,
                     intrinsics_.data())) {
    for (size_t i = 0; i < n; ++i) pixels[i].setConstant(kNaN);
    return;
  }
  for (size_t i = 0; i < n; ++i) {
    const Eigen::Vector3d& pc = points_in_cam[i];
    const bool visible = lens_->can_project_behind_camera ? pc.squaredNorm() > 0 : pc.z() > 0;
    if (!visible || !pixels[i].allFinite()) pixels[i].setConstant(kNaN);
  }
}

void CameraModel::UnprojectMany(const Eigen::Vector2d* pixels, size_t n,
                                Eigen::Vector3d* rays_in_cam) const {
  if (!valid()) throw std::logic_error("CameraModel::Unproject on an empty model");
  if (n == 0) return;
  const auto* q = reinterpret_cast<const mrcal_point2_t*>(pixels);
  auto* v = reinterpret_cast<mrcal_point3_t*>(rays_in_cam);
  // libmrcal 2.2 cannot unproject CAHVORE (and says so on stderr at every call).
  if (lens_->model.type == MRCAL_LENSMODEL_CAHVORE ||
      !mrcal_unproject(v, q, static_cast<int>(n), &lens_->model, intrinsics_.data())) {
    for (size_t i = 0; i < n; ++i) rays_in_cam[i].setConstant(kNaN);
    return;
  }
  for (size_t i = 0; i < n; ++i) {
    const double norm = rays_in_cam[i].norm();
    if (norm > 0 && std::isfinite(norm)) {
      rays_in_cam[i] /= norm;
    } else {
      rays_in_cam[i].setConstant(kNaN);
    }
  }
}

Eigen::Vector2d CameraModel::Project(const Eigen::Vector3d& point_in_cam) const {
  Eigen::Vector2d q;
  ProjectMany(&point_in_cam, 1, &q);
  return q;
}

Eigen::Vector3d CameraModel::Unproject(const Eigen::Vector2d& pixel) const {
  Eigen::Vector3d v;
  UnprojectMany(&pixel, 1, &v);
  return v;
}

Eigen::Vector2d CameraModel::ProjectGround(const Eigen::Vector3d& point_in_ground) const {
  return Project(cam_from_ground_ * point_in_ground);
}

Ray CameraModel::RayInGround(const Eigen::Vector2d& pixel) const {
  return {CentreInGround(), cam_from_ground_.rotation.transpose() * Unproject(pixel)};
}

}  // namespace ss
