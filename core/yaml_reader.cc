#include "core/yaml_reader.h"

#include <algorithm>
#include <filesystem>
#include <sstream>

#include <yaml-cpp/depthguard.h>

#include "core/error.h"

namespace ss {

namespace yaml_text {
namespace {

size_t EditDistance(const std::string& a, const std::string& b) {
  std::vector<size_t> row(b.size() + 1);
  for (size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (size_t i = 1; i <= a.size(); ++i) {
    size_t diag = row[0];
    row[0] = i;
    for (size_t j = 1; j <= b.size(); ++j) {
      const size_t up = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diag + (a[i - 1] == b[j - 1] ? 0 : 1)});
      diag = up;
    }
  }
  return row[b.size()];
}

}  // namespace

std::string Join(const std::vector<std::string>& items, const std::string& sep) {
  std::string out;
  for (size_t i = 0; i < items.size(); ++i) out += (i ? sep : "") + items[i];
  return out;
}

bool OneOf(const std::string& value, const std::vector<std::string>& options) {
  return std::find(options.begin(), options.end(), value) != options.end();
}

std::string Quoted(const std::string& s) {
  // A message names a value, it does not repeat it: a 10 MiB name made a 20 MB error.
  constexpr size_t kShown = 64;
  if (s.size() <= kShown) return "\"" + s + "\"";
  return "\"" + s.substr(0, kShown) + "...\" (" + std::to_string(s.size()) + " characters)";
}

std::string Num(double v) {
  std::ostringstream s;
  s << v;
  return s.str();
}

std::string Suggest(const std::string& key, const std::vector<std::string>& known) {
  std::string best;
  size_t best_d = std::max<size_t>(2, key.size() / 3) + 1;
  for (const auto& k : known) {
    const size_t d = EditDistance(key, k);
    if (d < best_d) {
      best_d = d;
      best = k;
    }
  }
  return best.empty() ? "" : " (did you mean " + Quoted(best) + "?)";
}

std::string Child(const std::string& path, const std::string& key) {
  return path.empty() ? key : path + "." + key;
}

std::string Index(const std::string& path, size_t i) {
  return path + "[" + std::to_string(i) + "]";
}

YAML::Node LoadOneDocument(const std::string& text, const std::string& origin) {
  const auto at = [&origin](const YAML::Mark& mark) {
    return mark.is_null() ? origin : origin + ":" + std::to_string(mark.line + 1);
  };
  // A second document is found in the text, not with YAML::LoadAll: yaml-cpp 0.7's LoadAll
  // never returns on some malformed input (a 425-byte config with a run of 0xFF bytes grew
  // without end; the config fuzz target's timeout), where Load stops at its error.
  // The line of the `---` that starts a second document: a marker after the first document's
  // content, or a second marker; a `...` end followed by more content starts one too.
  std::istringstream lines(text);
  std::string line;
  int markers = 0;
  bool content = false;  // the first document has begun
  bool ended = false;    // a `...` closed it
  for (int number = 0; std::getline(lines, line); ++number) {
    const auto marker = [&line](const char* m) {
      return line.rfind(m, 0) == 0 &&
             (line.size() == 3 || line[3] == ' ' || line[3] == '\t' || line[3] == '\r');
    };
    const bool start = marker("---");
    const bool blank_or_comment =
        line.find_first_not_of(" \t\r") == std::string::npos || line[0] == '#' || line[0] == '%';
    if ((start && (markers++ > 0 || content)) || (ended && !blank_or_comment)) {
      throw InputError(origin + ":" + std::to_string(number + 1),
                       "a second YAML document (---) starts here; the file must hold one document");
    }
    if (marker("...") && content) ended = true;
    if (!start && !blank_or_comment) content = true;
  }
  try {
    return YAML::Load(text);
  } catch (const YAML::DeepRecursion& e) {
    // yaml-cpp's own limit, which it reports as "bad file".
    throw InputError(at(e.mark), "nested deeper than " + std::to_string(e.depth() - 1) + " levels");
  } catch (const YAML::Exception& e) {
    throw InputError(at(e.mark), "not valid YAML: " + e.msg);
  }
}

int LineOf(const YAML::Node& node) {
  const YAML::Mark mark = node.Mark();
  return mark.is_null() ? 0 : mark.line + 1;
}

std::string ShapeOf(const YAML::Node& node) {
  if (node.IsScalar()) return Quoted(node.Scalar());
  if (node.IsSequence()) return "a list";
  if (node.IsMap()) return "a mapping";
  return "nothing";
}

}  // namespace yaml_text

using namespace yaml_text;

void YamlMessages::Error(const std::string& path, const std::string& reason,
                         const std::string& line_of) {
  errors.push_back(Where(line_of.empty() ? path : line_of) + path + ": " + reason);
  failed.insert(path);
}

void YamlMessages::Adjust(const std::string& path, const std::string& what) {
  adjustments.push_back(Where(path) + path + ": " + what);
}

std::string YamlMessages::Where(std::string path) const {
  while (!path.empty()) {
    const auto it = lines_.find(path);
    if (it != lines_.end()) return origin_ + ":" + std::to_string(it->second) + ": ";
    const size_t cut = path.find_last_of(".[");
    path = cut == std::string::npos ? "" : path.substr(0, cut);
  }
  return origin_ + ": ";
}

YamlMap::YamlMap(const YAML::Node& node, std::string path, YamlMessages& msg,
                 std::map<std::string, int>& lines)
    : path_(std::move(path)) {
  if (!node.IsMap()) {
    if (!node.IsNull()) {
      const std::string name = path_.empty() ? "(top level)" : path_;
      lines.emplace(name, LineOf(node));
      msg.Error(name, "expected a mapping of keys, got " + ShapeOf(node));
    }
    return;
  }
  for (auto it = node.begin(); it != node.end(); ++it) {
    const std::string key = it->first.IsScalar() ? it->first.Scalar() : "";
    const std::string field = Child(path_, key);
    if (key.empty()) {
      const std::string name = path_.empty() ? "(top level)" : path_;
      lines.emplace(name, LineOf(it->first));
      msg.Error(name,
                "a key at line " + std::to_string(LineOf(it->first)) + " is not a plain name");
      continue;
    }
    if (entries_.count(key)) {
      lines[field] = LineOf(it->first);
      msg.Error(field, "given twice (lines " + std::to_string(LineOf(entries_[key].key)) + " and " +
                           std::to_string(LineOf(it->first)) + ")");
      continue;
    }
    entries_[key] = {it->first, it->second};
    lines[field] = LineOf(it->first);
  }
}

const YAML::Node* YamlMap::Find(const std::string& key) const {
  const auto it = entries_.find(key);
  return it == entries_.end() ? nullptr : &it->second.value;
}

void YamlReader::Known(const YamlMap& view, const std::vector<std::string>& known) {
  for (const auto& [key, entry] : view.entries()) {
    if (!OneOf(key, known))
      msg_.Error(Child(view.path(), key), "unknown key" + Suggest(key, known));
  }
}

const YAML::Node* YamlReader::Value(const YamlMap& view, const std::string& key) {
  const YAML::Node* node = view.Find(key);
  if (node && node->IsNull()) {
    msg_.Error(Child(view.path(), key), "has no value (remove the key to use the default)");
    return nullptr;
  }
  return node;
}

bool YamlReader::Int64(const YamlMap& view, const std::string& key, int64_t& out,
                       const std::string& expected) {
  long long v = 0;
  if (!Scalar(view, key, v, expected)) return false;
  out = v;
  return true;
}

bool YamlReader::String(const YamlMap& view, const std::string& key, std::string& out,
                        const std::string& expected) {
  const YAML::Node* node = Value(view, key);
  if (!node) return false;
  if (!node->IsScalar()) {
    msg_.Error(Child(view.path(), key), "expected " + expected + ", got " + ShapeOf(*node));
    return false;
  }
  out = node->Scalar();
  return true;
}

bool YamlReader::Path(const YamlMap& view, const std::string& key, std::string& out) {
  std::string raw;
  if (!String(view, key, raw, "a path")) return false;
  if (raw.empty()) {
    msg_.Error(Child(view.path(), key), "expected a path, got \"\"");
    return false;
  }
  out = Resolve(raw);
  return true;
}

std::string YamlReader::Resolve(const std::string& raw) const {
  std::filesystem::path p(raw);
  if (p.is_relative()) p = std::filesystem::path(base_dir_) / p;
  return p.lexically_normal().string();
}

}  // namespace ss
