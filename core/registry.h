#pragma once
// Parts that register themselves by name (libcamera's REGISTER_PIPELINE_HANDLER): camera
// backends (capture/camera_backend.h) and keyers (pipeline/key/keyer_registry.h). Each part's
// own files define `void Register<Name><Kind>()`, and one CMake line
// (spritestation_registrations, cmake/Helpers.cmake) generates the function that calls them
// all; the registry calls it on first use, so nothing else in the project names a part.
#include <map>
#include <mutex>
#include <string>
#include <vector>

#include "core/error.h"

namespace ss {

template <typename Part>
class PartRegistry {
 public:
  // `kind` names the parts in errors ("camera backend"); `register_built_in` is the generated
  // function that registers every part built in.
  PartRegistry(std::string kind, void (*register_built_in)())
      : kind_(std::move(kind)), register_built_in_(register_built_in) {}

  // A second part of the same name is a bug: WorkError.
  void Add(const std::string& name, Part part) {
    if (!parts_.emplace(name, std::move(part)).second)
      throw WorkError(kind_ + " " + name, "registered twice");
  }
  // nullptr when no part of that name is built in.
  const Part* Find(const std::string& name) {
    const auto& parts = BuiltIn();
    const auto it = parts.find(name);
    return it == parts.end() ? nullptr : &it->second;
  }
  // Every part built in, by name.
  std::vector<const Part*> All() {
    std::vector<const Part*> out;
    for (const auto& [name, part] : BuiltIn()) out.push_back(&part);
    return out;
  }
  std::vector<std::string> Names() {
    std::vector<std::string> out;
    for (const auto& [name, part] : BuiltIn()) out.push_back(name);
    return out;
  }

 private:
  const std::map<std::string, Part>& BuiltIn() {
    std::call_once(once_, register_built_in_);
    return parts_;
  }
  std::string kind_;
  void (*register_built_in_)();
  std::once_flag once_;
  std::map<std::string, Part> parts_;
};

}  // namespace ss
