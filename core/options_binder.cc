#include "core/options_binder.h"

#include <cmath>
#include <stdexcept>
#include <utility>

namespace ss {
namespace {

using namespace yaml_text;

// "chroma" and "low" of "chroma.low"; "method" and "" of "method".
std::pair<std::string, std::string> SplitFirst(const std::string& key) {
  const size_t dot = key.find('.');
  if (dot == std::string::npos) return {key, ""};
  return {key.substr(0, dot), key.substr(dot + 1)};
}

}  // namespace

OptionsBinder& OptionsBinder::Bind(std::string key, std::string type, std::string default_text,
                                   std::string doc, ReadFn read) {
  if (doc.empty()) throw std::logic_error("config key \"" + key + "\" bound without a doc");
  bindings_.push_back({std::move(key), std::move(type), std::move(default_text), false,
                       std::move(doc), std::move(read)});
  return *this;
}

OptionsBinder& OptionsBinder::AddRead(std::string key, std::string default_text, std::string doc,
                                      ReadFn read) {
  return Bind(std::move(key), "", std::move(default_text), std::move(doc), std::move(read));
}

std::string OptionsBinder::Choices(const std::vector<std::string>& texts) {
  std::string out;
  for (const std::string& t : texts) out += (out.empty() ? "`" : " | `") + t + "`";
  return out;
}

OptionsBinder& OptionsBinder::Type(std::string type) {
  if (bindings_.empty()) throw std::logic_error("Type() before any key was bound");
  bindings_.back().type = std::move(type);
  bindings_.back().type_given = true;
  return *this;
}

OptionsBinder& OptionsBinder::Rule(NumberRule rule) {
  if (bindings_.empty() || !bindings_.back().number)
    throw std::logic_error("Rule() on a key that is not a number");
  bindings_.back().rule = rule;
  return *this;
}

void OptionsBinder::CheckRules(YamlMessages& msg, const std::string& path) const {
  CheckRules(msg, path, nullptr);
}

void OptionsBinder::CheckRules(YamlMessages& msg, const YamlMap& given) const {
  CheckRules(msg, given.path(), &given);
}

void OptionsBinder::CheckRules(YamlMessages& msg, const std::string& path,
                               const YamlMap* given) const {
  for (const Binding& b : bindings_) {
    if (!b.rule || (given != nullptr && given->Find(b.key) == nullptr)) continue;
    const std::optional<double> v = b.number();
    const std::string key = Child(path, b.key);
    if (v && !b.rule->Holds(*v) && !msg.Failed(key))
      msg.Error(key, "expected " + b.expected + ", got " + Num(*v));
  }
}

std::string NumberRule::Text() const {
  if (max < 1e300) {
    if (!min_open && !max_open) return Num(min) + ".." + Num(max);
    return (min_open ? "> " : ">= ") + Num(min) + (max_open ? ", < " : ", <= ") + Num(max);
  }
  return (min_open ? "> " : ">= ") + Num(min);
}

OptionsBinder& OptionsBinder::Default(std::string words) {
  if (bindings_.empty()) throw std::logic_error("Default() before any key was bound");
  bindings_.back().default_text = std::move(words);
  bindings_.back().default_in_words = true;
  return *this;
}

OptionsBinder& OptionsBinder::BindNumber(std::string key, std::string type,
                                         std::string default_text, std::string doc,
                                         std::string expected, ReadFn read,
                                         std::function<std::optional<double>()> value) {
  Bind(std::move(key), std::move(type), std::move(default_text), std::move(doc), std::move(read));
  bindings_.back().expected = std::move(expected);
  bindings_.back().number = std::move(value);
  return *this;
}

OptionsBinder& OptionsBinder::Add(std::string key, int* field, const std::string& expected,
                                  std::string doc) {
  return BindNumber(
      std::move(key), "integer", std::to_string(*field), std::move(doc), expected,
      [field, expected](YamlReader& r, const YamlMap& view, const std::string& k) {
        return r.Int(view, k, *field, expected);
      },
      [field] { return std::optional<double>(*field); });
}

OptionsBinder& OptionsBinder::Add(std::string key, int64_t* field, const std::string& expected,
                                  std::string doc) {
  return BindNumber(
      std::move(key), "integer", std::to_string(*field), std::move(doc), expected,
      [field, expected](YamlReader& r, const YamlMap& view, const std::string& k) {
        return r.Int64(view, k, *field, expected);
      },
      [field] { return std::optional<double>(static_cast<double>(*field)); });
}

OptionsBinder& OptionsBinder::Add(std::string key, double* field, const std::string& expected,
                                  std::string doc) {
  return BindNumber(
      std::move(key), "number", Num(*field), std::move(doc), expected,
      [field, expected](YamlReader& r, const YamlMap& view, const std::string& k) {
        return r.Number(view, k, *field, expected);
      },
      [field] { return std::optional<double>(*field); });
}

OptionsBinder& OptionsBinder::Add(std::string key, std::optional<double>* field,
                                  const std::string& expected, std::string doc) {
  return BindNumber(
      std::move(key), "number", *field ? Num(**field) : "unset", std::move(doc), expected,
      [field, expected](YamlReader& r, const YamlMap& view, const std::string& k) {
        double v = 0;
        if (!r.Number(view, k, v, expected)) return false;
        *field = v;
        return true;
      },
      [field] { return *field; });
}

OptionsBinder& OptionsBinder::Add(std::string key, bool* field, std::string doc) {
  return Bind(std::move(key), "bool", *field ? "true" : "false", std::move(doc),
              [field](YamlReader& r, const YamlMap& view, const std::string& k) {
                return r.Bool(view, k, *field);
              });
}

OptionsBinder& OptionsBinder::Add(std::string key, std::string* field, std::string expected,
                                  std::string doc) {
  return Bind(std::move(key), "string", field->empty() ? "\"\"" : *field, std::move(doc),
              [field, expected = std::move(expected)](YamlReader& r, const YamlMap& view,
                                                      const std::string& k) {
                return r.String(view, k, *field, expected);
              });
}

OptionsBinder& OptionsBinder::AddPath(std::string key, std::string* field, std::string doc) {
  return Bind(std::move(key), "path", field->empty() ? "\"\"" : *field, std::move(doc),
              [field](YamlReader& r, const YamlMap& view, const std::string& k) {
                return r.Path(view, k, *field);
              });
}

void OptionsBinder::Read(YamlReader& r, const YAML::Node& node, const std::string& path) const {
  const YamlMap view = r.Map(node, path);
  std::vector<std::string> known;
  for (const Binding& b : bindings_) {
    const std::string first = SplitFirst(b.key).first;
    if (!OneOf(first, known)) known.push_back(first);
  }
  r.Known(view, known);
  ReadKeys(r, view);
}

void OptionsBinder::ReadKeys(YamlReader& r, const YamlMap& view) const {
  std::vector<std::string> done;  // nested blocks already read
  for (const Binding& b : bindings_) {
    const auto [first, rest] = SplitFirst(b.key);
    if (rest.empty()) {
      b.read(r, view, first);
      continue;
    }
    if (OneOf(first, done)) continue;
    done.push_back(first);
    // The nested block: every binding under `first.`, read from its own mapping.
    OptionsBinder block;
    for (const Binding& inner : bindings_) {
      const auto [inner_first, inner_rest] = SplitFirst(inner.key);
      if (inner_first == first && !inner_rest.empty()) {
        Binding b = inner;
        b.key = inner_rest;
        block.bindings_.push_back(std::move(b));
      }
    }
    if (const YAML::Node* n = r.Value(view, first)) block.Read(r, *n, Child(view.path(), first));
  }
}

std::vector<std::string> OptionsBinder::Keys() const {
  std::vector<std::string> keys;
  for (const Binding& b : bindings_) keys.push_back(b.key);
  return keys;
}

std::vector<OptionsBinder::Row> OptionsBinder::Rows() const {
  std::vector<Row> rows;
  for (const Binding& b : bindings_) {
    if (b.type.empty()) throw std::logic_error("config key \"" + b.key + "\" bound without a type");
    const std::string type = b.rule && !b.type_given ? b.type + " " + b.rule->Text() : b.type;
    rows.push_back(
        {b.key, type, b.default_in_words ? b.default_text : "`" + b.default_text + "`", b.doc});
  }
  return rows;
}

}  // namespace ss
