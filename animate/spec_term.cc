#include "animate/spec_term.h"

#include "core/options_binder.h"
#include "core/registry.h"
#include "core/yaml_reader.h"

namespace ss {

void RegisterBuiltInSpecTerms();  // generated: animate/CMakeLists.txt

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

std::shared_ptr<const SpecTerm> ReadTermBlock(SpecBlockReader& reader, const YAML::Node& node,
                                              const std::string& path,
                                              std::shared_ptr<SpecTerm> term,
                                              const std::function<void(OptionsBinder&)>& bind,
                                              const std::vector<const char*>& required) {
  OptionsBinder keys;
  bind(keys);
  YamlMap view;
  if (reader.Block(keys, node, path, view)) {
    for (const char* key : required) reader.Required(view, key, "required");
  }
  return term;
}

}  // namespace ss
