#include "animate/spec_term.h"

#include "core/registry.h"

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

}  // namespace ss
