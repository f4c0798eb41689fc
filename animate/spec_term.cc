#include "animate/spec_term.h"

#include <iterator>

#include "core/error.h"
#include "core/options_binder.h"
#include "core/registry.h"
#include "core/yaml_reader.h"

namespace ss {

void RegisterBuiltInSpecTerms();          // generated: animate/CMakeLists.txt
void RegisterBuiltInSpriteConstraints();  // the same (none yet)

namespace {

PartRegistry<SpecTermKind>& SpecTerms() {
  static PartRegistry<SpecTermKind> registry("spec term", RegisterBuiltInSpecTerms);
  return registry;
}

}  // namespace

void RegisterSpecTerm(SpecTermKind kind) {
  const std::string key = kind.key;
  SpecTerms().Add(key, std::move(kind));
}

std::vector<const SpecTermKind*> SpecTermKinds() { return SpecTerms().All(); }

void ReadSpecBlock(SpecBlockReader& reader, const YAML::Node& node, const std::string& path,
                   const std::function<void(OptionsBinder&)>& bind,
                   const std::vector<const char*>& required) {
  OptionsBinder keys;
  bind(keys);
  YamlMap view;
  if (reader.Block(keys, node, path, view)) {
    for (const char* key : required) reader.Required(view, key, "required");
  }
}

namespace {

// The constraints that are the spec's typed fields (SpriteSpecEntry), read by animate/spec.cc.
constexpr const char* kTypedConstraints[] = {"location", "path", "frames"};

PartRegistry<SpriteConstraintKind>& SpriteConstraints() {
  static PartRegistry<SpriteConstraintKind> registry("sprite constraint",
                                                     RegisterBuiltInSpriteConstraints);
  return registry;
}

}  // namespace

void RegisterSpriteConstraint(SpriteConstraintKind kind) {
  const std::string key = kind.key;
  for (const char* typed : kTypedConstraints) {
    if (key == typed) throw WorkError("sprite constraint " + key, "is one of the spec's own");
  }
  SpriteConstraints().Add(key, std::move(kind));
}

const SpriteConstraintKind* FindSpriteConstraint(const std::string& key) {
  return SpriteConstraints().Find(key);
}

std::vector<std::string> SpriteConstraintKeys() {
  std::vector<std::string> keys(std::begin(kTypedConstraints), std::end(kTypedConstraints));
  for (const std::string& key : SpriteConstraints().Names()) keys.push_back(key);
  return keys;
}

}  // namespace ss
