#pragma once
// Config keys bound straight to option fields (COLMAP's option_manager binds
// "ImageReader.mask_path" to &image_reader->mask_path): one list per block says each key's
// field, type, expected value and doc, and its default is the field's value when bound. Read()
// sets every key given, refuses unknown keys by name (with a near miss suggested) and names
// ORIGIN:LINE: the.full.key in every error (core/yaml_reader.h). Keys with dots are nested
// blocks: "chroma.low" is `low:` inside `chroma:`.
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "core/option_checks.h"  // NumberRule
#include "core/yaml_reader.h"

namespace ss {

class OptionsBinder {
 public:
  // Reads one key of `view` (whose path is the block's) into its field; true when it set it.
  using ReadFn = std::function<bool(YamlReader& r, const YamlMap& view, const std::string& key)>;

  // `expected` completes "expected ..., got ..." when the value has the wrong type.
  OptionsBinder& Add(std::string key, int* field, const std::string& expected, std::string doc);
  OptionsBinder& Add(std::string key, int64_t* field, const std::string& expected, std::string doc);
  OptionsBinder& Add(std::string key, double* field, const std::string& expected, std::string doc);
  OptionsBinder& Add(std::string key, std::optional<double>* field, const std::string& expected,
                     std::string doc);
  OptionsBinder& Add(std::string key, bool* field, std::string doc);
  OptionsBinder& Add(std::string key, std::string* field, std::string expected, std::string doc);
  // A file or folder, resolved against the file's folder.
  OptionsBinder& AddPath(std::string key, std::string* field, std::string doc);
  // One of a closed set's texts (core/enum_text.h).
  template <typename E, size_t N>
  OptionsBinder& AddEnum(std::string key, E* field, const EnumText<E> (&texts)[N],
                         std::string doc) {
    std::vector<std::string> names;
    for (const EnumText<E>& t : texts) names.emplace_back(t.text);
    return Bind(std::move(key), Choices(names), TextOf(*field, texts), std::move(doc),
                [field, &texts](YamlReader& r, const YamlMap& view, const std::string& k) {
                  return r.Enum(view, k, *field, texts);
                });
  }
  // A key whose value has a shape of its own (`auto` or a number, a list of points...); its
  // type for the docs is given with Type().
  OptionsBinder& AddRead(std::string key, std::string default_text, std::string doc, ReadFn read);

  // A closed set as a type: "`a` | `b` | `c`".
  static std::string Choices(const std::vector<std::string>& texts);

  // Of the key bound last: its type as the docs' key tables say it ("integer >= 1"; by default
  // the field's: integer, number, bool, string, path, or the enum's texts)...
  OptionsBinder& Type(std::string type);
  // ... and its default when that is not the field's value: words ("required", "the device's
  // current value"), written into the tables as they are.
  OptionsBinder& Default(std::string words);
  // ... and its bounds, when it is a number (else std::logic_error).
  OptionsBinder& Rule(NumberRule rule);

  // Reports every bound number out of its rule at its key under `path` ("cameras[0]"), unless
  // that key has an error already.
  void CheckRules(YamlMessages& msg, const std::string& path) const;
  // The same for the keys `given` holds only (a file's block whose unset keys are not checked:
  // the animation spec, where a required key's absence is its own error).
  void CheckRules(YamlMessages& msg, const YamlMap& given) const;

  // Reads the mapping `node` at `path` ("" for the top level): unknown keys first, then each
  // bound key in the order it was bound. Reports to r.msg(); never throws.
  void Read(YamlReader& r, const YAML::Node& node, const std::string& path) const;
  // The same on a mapping already opened, without the unknown-key check (a block whose keys
  // depend on another key's value checks them itself).
  void ReadKeys(YamlReader& r, const YamlMap& view) const;

  // Every key bound, with dots, in the order bound.
  std::vector<std::string> Keys() const;
  // One row of a key table (docs/config.md, `spritestation config keys --markdown`): every
  // cell in Markdown, the default as code unless given in words.
  struct Row {
    std::string key, type, default_cell, doc;
  };
  // Every key bound, in the order bound; throws std::logic_error naming a key bound without
  // its type or doc (a key the docs cannot describe is a defect of the code, not of a config).
  std::vector<Row> Rows() const;

 private:
  // CheckRules on the keys at `path`: every bound number, or those `given` holds (non-null).
  void CheckRules(YamlMessages& msg, const std::string& path, const YamlMap* given) const;

  struct Binding {
    std::string key;  // relative to the block, dotted
    std::string type;
    std::string default_text;
    bool default_in_words = false;
    std::string doc;
    ReadFn read;
    std::string expected;                           // a number's words for its messages
    std::function<std::optional<double>()> number;  // a number's value (none: unset)
    std::optional<NumberRule> rule;
    bool type_given = false;  // Type() said it all
  };
  OptionsBinder& Bind(std::string key, std::string type, std::string default_text, std::string doc,
                      ReadFn read);
  OptionsBinder& BindNumber(std::string key, std::string type, std::string default_text,
                            std::string doc, std::string expected, ReadFn read,
                            std::function<std::optional<double>()> value);
  std::vector<Binding> bindings_;
};

}  // namespace ss
