#pragma once
// Reading YAML files that people write (the station config, the animation spec): every error
// names the file, the line and the full key (`station.yaml:14: cameras[1].fps: expected a
// positive number, got "fast"`); unknown keys are refused by name with a near miss suggested;
// every error of a file is collected before the caller throws. OptionsBinder
// (core/options_binder.h) binds keys to option fields on top of this.
#include <cstddef>
#include <map>
#include <set>
#include <string>
#include <vector>

#include <yaml-cpp/yaml.h>

#include "core/enum_text.h"

namespace ss {

namespace yaml_text {
std::string Join(const std::vector<std::string>& items, const std::string& sep = ", ");
bool OneOf(const std::string& value, const std::vector<std::string>& options);
std::string Quoted(const std::string& s);
std::string Num(double v);  // short form of a number for messages ("25", "0.5")
// " (did you mean "fps"?)" for a near miss among `known`, else "".
std::string Suggest(const std::string& key, const std::vector<std::string>& known);
std::string Child(const std::string& path, const std::string& key);  // "a.b"
std::string Index(const std::string& path, size_t i);                // "a[3]"
// Parses `text` as one YAML document; InputError naming `origin` and the line when it is not
// valid YAML, is nested deeper than yaml-cpp reads, or holds a second document (which yaml-cpp's
// Load would drop without a word). An empty text is a null node.
YAML::Node LoadOneDocument(const std::string& text, const std::string& origin);
int LineOf(const YAML::Node& node);           // 1-based; 0 when unknown
std::string ShapeOf(const YAML::Node& node);  // "\"text\"", "a list", "a mapping", "nothing"
}  // namespace yaml_text

// Errors and adjustments, each tied to a field path and its YAML line.
class YamlMessages {
 public:
  YamlMessages(std::string origin, const std::map<std::string, int>& lines)
      : origin_(std::move(origin)), lines_(lines) {}
  // `line_of` names the field whose line to show, when it is not `path` itself.
  void Error(const std::string& path, const std::string& reason, const std::string& line_of = "");
  void Adjust(const std::string& path, const std::string& what);
  bool Failed(const std::string& path) const { return failed.count(path) > 0; }

  std::vector<std::string> errors, adjustments;  // "ORIGIN:LINE: PATH: reason"
  std::set<std::string> failed;                  // paths that already have an error

 private:
  // "ORIGIN:LINE: " with the line of the field or, if it is absent, of its nearest parent.
  std::string Where(std::string path) const;
  std::string origin_;
  const std::map<std::string, int>& lines_;
};

// One YAML mapping: its entries by key, with duplicate keys and a non-mapping reported.
class YamlMap {
 public:
  struct Entry {
    YAML::Node key, value;
  };
  YamlMap() = default;
  YamlMap(const YAML::Node& node, std::string path, YamlMessages& msg,
          std::map<std::string, int>& lines);
  const std::string& path() const { return path_; }
  const std::map<std::string, Entry>& entries() const { return entries_; }
  const YAML::Node* Find(const std::string& key) const;

 private:
  std::string path_;
  std::map<std::string, Entry> entries_;
};

// Reads values out of mappings into fields, recording each field's line and reporting every
// mistake to `msg` without throwing. Each reader returns true when it set `out`.
class YamlReader {
 public:
  YamlReader(YamlMessages& msg, std::map<std::string, int>& lines, std::string base_dir)
      : msg_(msg), lines_(lines), base_dir_(std::move(base_dir)) {}

  YamlMap Map(const YAML::Node& node, const std::string& path) {
    return YamlMap(node, path, msg_, lines_);
  }
  // Reports every key of `view` not in `known`.
  void Known(const YamlMap& view, const std::vector<std::string>& known);
  // The value node of `key`, or nullptr when absent. An explicit null is an error.
  const YAML::Node* Value(const YamlMap& view, const std::string& key);

  template <typename T>
  bool Scalar(const YamlMap& view, const std::string& key, T& out, const std::string& expected) {
    const YAML::Node* node = Value(view, key);
    if (!node) return false;
    T value{};
    if (!node->IsScalar() || !YAML::convert<T>::decode(*node, value)) {
      msg_.Error(yaml_text::Child(view.path(), key),
                 "expected " + expected + ", got " + yaml_text::ShapeOf(*node));
      return false;
    }
    out = value;
    return true;
  }
  bool Number(const YamlMap& view, const std::string& key, double& out,
              const std::string& expected = "a number") {
    return Scalar(view, key, out, expected);
  }
  bool Int(const YamlMap& view, const std::string& key, int& out,
           const std::string& expected = "an integer") {
    return Scalar(view, key, out, expected);
  }
  bool Int64(const YamlMap& view, const std::string& key, int64_t& out,
             const std::string& expected);
  bool Bool(const YamlMap& view, const std::string& key, bool& out) {
    return Scalar(view, key, out, "true or false");
  }
  bool String(const YamlMap& view, const std::string& key, std::string& out,
              const std::string& expected = "a string");
  // One of a closed set's texts, into its enum value; an error naming the field and every
  // allowed text otherwise.
  template <typename E, size_t N>
  bool Enum(const YamlMap& view, const std::string& key, E& out, const EnumText<E> (&texts)[N]) {
    std::string text;
    if (!String(view, key, text)) return false;
    return ToEnum(text, texts, yaml_text::Child(view.path(), key), out);
  }
  template <typename E, size_t N>
  bool ToEnum(const std::string& text, const EnumText<E> (&texts)[N], const std::string& path,
              E& out) {
    std::vector<std::string> names;
    for (const EnumText<E>& t : texts) {
      if (text == t.text) {
        out = t.value;
        return true;
      }
      names.push_back(t.text);
    }
    msg_.Error(path,
               "expected one of " + yaml_text::Join(names) + ", got " + yaml_text::Quoted(text));
    return false;
  }
  // A path, resolved against the file's folder.
  bool Path(const YamlMap& view, const std::string& key, std::string& out);
  std::string Resolve(const std::string& raw) const;

  YamlMessages& msg() { return msg_; }
  // Records where a list item sits, for messages about it.
  void Mark(const std::string& path, const YAML::Node& node) {
    lines_[path] = yaml_text::LineOf(node);
  }

 private:
  YamlMessages& msg_;
  std::map<std::string, int>& lines_;
  std::string base_dir_;
};

}  // namespace ss
