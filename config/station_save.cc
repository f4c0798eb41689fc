#include "config/station_save.h"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>

#include <yaml-cpp/yaml.h>
#include <nlohmann/json.hpp>

#include "calib/enclosure.h"
#include "core/error.h"
#include "core/log.h"
#include "core/posix.h"

namespace ss::calib {
namespace {

namespace fs = std::filesystem;

std::string Number(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.4f", v);
  return buf;
}

// Writes `bytes` to `path` and flushes them to the disk; WorkError naming the file.
void WriteDurably(const std::string& path, const std::string& bytes) {
  const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0)
    throw WorkError(fs::path(path).parent_path().string(),
                    std::string("cannot write there: ") + ErrnoText(errno));
  size_t done = 0;
  while (done < bytes.size()) {
    const ssize_t n = ::write(fd, bytes.data() + done, bytes.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      const int err = errno;
      ::close(fd);
      ::unlink(path.c_str());
      throw WorkError(path, std::string("cannot write: ") + ErrnoText(err));
    }
    done += static_cast<size_t>(n);
  }
  if (::fsync(fd) != 0 || ::close(fd) != 0) {
    const int err = errno;
    ::unlink(path.c_str());
    throw WorkError(path, std::string("cannot write: ") + ErrnoText(err));
  }
}

std::string ReadText(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw WorkError(path, "cannot read the config");
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

std::string JoinLines(const std::vector<std::string>& lines) {
  std::string out;
  for (const auto& l : lines) out += l + "\n";
  return out;
}

struct Pending {
  std::string target, temp;
};

}  // namespace

std::string PreviousFileName(const std::string& path, const std::string& stamp) {
  const fs::path p(path);
  return (p.parent_path() / (p.stem().string() + ".previous-" + stamp + p.extension().string()))
      .string();
}

std::string SetCameraModelPath(const std::string& config_yaml, const std::string& camera,
                               const std::string& path, const std::string& origin) {
  std::vector<std::string> lines;
  {
    std::istringstream in(config_yaml);
    std::string line;
    while (std::getline(in, line)) lines.push_back(line);
  }
  // The camera's "name:" line ("  - name: cam0" or "    name: cam0", the name maybe quoted).
  const std::regex name_line(R"(^(\s*(?:-\s+)?)name:\s*["']?([^"'#]*?)["']?\s*(#.*)?$)");
  const std::string value = nlohmann::json(path).dump();  // a JSON string is a YAML string
  // Or a flow mapping on one line ("  - {name: cam0, source: replay}"): read and written again
  // as one, the model set in it.
  const std::regex flow_line(R"(^(\s*-\s+)(\{.*\})(\s*#.*)?\s*$)");
  for (auto& line : lines) {
    std::smatch m;
    if (!std::regex_match(line, m, flow_line)) continue;
    YAML::Node entry;
    try {
      entry = YAML::Load(m[2].str());
    } catch (const YAML::Exception&) {
      continue;  // a "{" in a comment or a string: not this camera's entry
    }
    if (!entry.IsMap() || !entry["name"] || !entry["name"].IsScalar() ||
        entry["name"].Scalar() != camera)
      continue;
    entry["model"] = path;
    YAML::Emitter out;
    out.SetMapFormat(YAML::Flow);
    out << entry;
    line = m[1].str() + out.c_str() + m[3].str();
    return JoinLines(lines);
  }
  for (size_t i = 0; i < lines.size(); ++i) {
    std::smatch m;
    if (!std::regex_match(lines[i], m, name_line) || m[2].str() != camera) continue;
    const size_t column = m[1].length();  // where the entry's keys start
    const std::string indent(column, ' ');
    // The entry's lines: deeper than its dash, or keys at its column.
    size_t end = i + 1;
    while (end < lines.size()) {
      const std::string& l = lines[end];
      const size_t first = l.find_first_not_of(' ');
      if (first == std::string::npos || l[first] == '#') {
        ++end;
        continue;
      }
      if (first < column || (first == column && l[first] == '-')) break;
      ++end;
    }
    for (size_t k = i + 1; k < end; ++k) {
      if (lines[k].size() > column && lines[k].compare(0, column, indent) == 0 &&
          lines[k].compare(column, 6, "model:") == 0) {
        lines[k] = indent + "model: " + value;
        goto joined;
      }
    }
    lines.insert(lines.begin() + static_cast<std::ptrdiff_t>(i) + 1, indent + "model: " + value);
  joined:
    return JoinLines(lines);
  }
  throw InputError(origin, "no entry \"name: " + camera + "\" under cameras: to set its model in");
}

StationSaveResult SaveStationCalibration(const StationConfig& config,
                                         const StationSaveRequest& request) {
  StationSaveResult result;
  result.config = config;
  std::string yaml;
  if (!request.config_path.empty()) yaml = ReadText(request.config_path);
  std::vector<Pending> pending;
  auto cleanup = [&] {
    for (const auto& p : pending) ::unlink(p.temp.c_str());
  };
  const std::string suffix = ".saving-" + std::to_string(::getpid());
  try {
    for (const auto& [name, model] : request.models) {
      CameraConfig* camera = nullptr;
      for (auto& c : result.config.cameras) {
        if (c.name == name) camera = &c;
      }
      if (camera == nullptr) throw InputError(name, "not a camera of the station's config");
      std::string target = camera->model;
      if (target.empty()) {
        std::error_code ec;
        fs::create_directories(request.calibration_dir, ec);
        if (ec)
          throw WorkError(request.calibration_dir, "cannot create the folder: " + ec.message());
        target = fs::absolute(fs::path(request.calibration_dir) / (name + ".cameramodel"))
                     .lexically_normal()
                     .string();
        camera->model = target;
        if (!yaml.empty()) yaml = SetCameraModelPath(yaml, name, target, request.config_path);
      }
      pending.push_back({target, target + suffix});
      WriteDurably(pending.back().temp, model.ToText());
    }
    if (request.floor) {
      result.config.enclosure.floor = *request.floor;
      if (!yaml.empty()) yaml = ReplaceEnclosureFloor(yaml, *request.floor, request.config_path);
    }
    if (!request.config_path.empty()) {
      pending.push_back({request.config_path, request.config_path + suffix});
      WriteDurably(pending.back().temp, yaml);
    }
  } catch (...) {
    cleanup();
    throw;
  }
  // Every new file is on the disk: keep each old one under its new name, then swap.
  for (size_t i = 0; i < pending.size(); ++i) {
    const Pending& p = pending[i];
    if (!request.config_path.empty() && p.target == request.config_path) {
      // The models are in place now: the edited config must load as the station's, models and all.
      try {
        ParseStationConfig(yaml, request.config_path,
                           fs::path(request.config_path).parent_path().string());
      } catch (const std::exception& e) {
        ::unlink(p.temp.c_str());
        throw InputError(request.config_path,
                         std::string("the models were saved, but the config with them does not "
                                     "load (left as it was): ") +
                             e.what());
      }
    }
    std::error_code ec;
    if (fs::exists(p.target, ec)) {
      const std::string previous = PreviousFileName(p.target, request.stamp);
      if (::link(p.target.c_str(), previous.c_str()) != 0) {
        fs::copy_file(p.target, previous, fs::copy_options::overwrite_existing, ec);
        if (ec) {
          for (size_t k = i; k < pending.size(); ++k) ::unlink(pending[k].temp.c_str());
          throw WorkError(previous, "cannot keep the previous file: " + ec.message() +
                                        (i > 0 ? " (the files before it were saved)"
                                               : " (nothing was changed)"));
        }
      }
      result.previous.push_back(previous);
    }
    if (::rename(p.temp.c_str(), p.target.c_str()) != 0) {
      const int err = errno;
      for (size_t k = i; k < pending.size(); ++k) ::unlink(pending[k].temp.c_str());
      throw WorkError(p.target, std::string("cannot replace: ") + ErrnoText(err));
    }
    result.files.push_back(p.target);
  }
  Log("calib.save")
      ->info("calibration saved: {} file(s), {} previous kept", result.files.size(),
             result.previous.size());
  return result;
}

std::string ReplaceEnclosureFloor(const std::string& config_yaml, const GroundPolygon& floor,
                                  const std::string& origin) {
  std::vector<std::string> lines;
  {
    std::istringstream in(config_yaml);
    std::string line;
    while (std::getline(in, line)) lines.push_back(line);
  }
  auto indent = [](const std::string& l) { return l.find_first_not_of(' '); };
  auto blank = [&](const std::string& l) {
    const size_t i = indent(l);
    return i == std::string::npos || l[i] == '#';
  };
  std::ostringstream floor_text;
  for (const auto& v : floor.vertices())
    floor_text << "    - [" << Number(v.x()) << ", " << Number(v.y()) << "]\n";
  std::vector<std::string> out;
  size_t i = 0;
  bool done = false;
  for (; i < lines.size(); ++i) {
    if (!done && lines[i].rfind("enclosure:", 0) == 0) {
      out.push_back(lines[i]);
      size_t end = i + 1;
      while (end < lines.size() && (blank(lines[end]) || indent(lines[end]) > 0)) ++end;
      bool replaced = false;
      for (size_t k = i + 1; k < end; ++k) {
        const size_t in = indent(lines[k]);
        if (!blank(lines[k]) && lines[k].compare(in, 6, "floor:") == 0) {
          out.push_back(lines[k].substr(0, in) + "floor:");
          size_t j = k + 1;
          while (j < end && (blank(lines[j]) || indent(lines[j]) > in ||
                             (indent(lines[j]) == in && lines[j][in] == '-'))) {
            ++j;
          }
          std::istringstream f(floor_text.str());
          std::string fl;
          while (std::getline(f, fl))
            out.push_back(std::string(in + 2, ' ') + fl.substr(fl.find('-')));
          k = j - 1;
          replaced = true;
        } else {
          out.push_back(lines[k]);
        }
      }
      if (!replaced) {
        out.push_back("  floor:");
        std::istringstream f(floor_text.str());
        std::string fl;
        while (std::getline(f, fl)) out.push_back(fl);
      }
      i = end - 1;
      done = true;
    } else {
      out.push_back(lines[i]);
    }
  }
  std::string result;
  for (const auto& l : out) result += l + "\n";
  if (!done) result += EnclosureYaml(floor, 0.0);
  ConfigOptions check;
  check.check_files = false;
  ParseStationConfig(result, origin, ".", nullptr, check);  // throws InputError naming the line
  return result;
}

}  // namespace ss::calib
