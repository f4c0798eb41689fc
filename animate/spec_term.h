#pragma once
// Cost terms a spec turns on with a top-level block of their own (`repeats:`, `facing:`,
// `clones:`), and a sprite's constraints beyond location, path and frames (SpriteConstraint,
// below), registered as keyers and camera backends are (core/registry.h): a term's own files
// define `void Register<Name>SpecTerm()`, which calls RegisterSpecTerm with how it reads its
// block and which terms it adds to a scene, and one line in animate/CMakeLists.txt
// (spritestation_registrations) builds the call in. The spec reader (animate/spec.cc) and the
// scene (animate/scene.cc) name no such term.
#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace YAML {
class Node;
}

namespace ss {

class OptionsBinder;
class Problem;
class TransitionGraph;
class YamlMap;

// The spec reader's rules, for a term's block: each mistake is reported with its line and key,
// and the spec is refused with every mistake of the file.
class SpecBlockReader {
 public:
  virtual ~SpecBlockReader() = default;
  // Reads the mapping `node` at `path` with `keys` into `view`: unknown keys, wrong types and
  // each binding's rule (`.Rule(AtLeast(0))`) on the keys given, each at its key. False when it
  // is not a mapping (reported).
  virtual bool Block(const OptionsBinder& keys, const YAML::Node& node, const std::string& path,
                     YamlMap& view) = 0;
  // Reports `reason` at `key` when the block lacks it.
  virtual void Required(const YamlMap& view, const std::string& key, const std::string& reason) = 0;
};

// One term's block as read: what it adds to a scene.
class SpecTerm {
 public:
  virtual ~SpecTerm() = default;
  // Adds its cost terms for the problem's sprites (every sprite is added by then).
  virtual void AddTerms(const TransitionGraph& graph, Problem& problem) const = 0;
  // The tags whose frames it reads (the banks are loaded with them marked: LoadBankGraph).
  virtual std::vector<std::string> Tags() const { return {}; }
};

struct SpecTermKind {
  std::string key;       // its top-level key in the spec
  std::string expected;  // its block in words, for errors and docs: "{strength, lag_steps}"
  // Reads its block at `path` (a mistake reported through `reader`, never thrown).
  std::function<std::shared_ptr<const SpecTerm>(SpecBlockReader& reader, const YAML::Node& node,
                                                const std::string& path)>
      read;
  // What a spec without the block gets (nullptr: the term is off).
  std::function<std::shared_ptr<const SpecTerm>()> absent = [] { return nullptr; };
};

// Reads a registered block: `bind` binds its keys to the fields of what it reads, and each key
// of `required` is reported when the block lacks it (a mistake reported through `reader`).
void ReadSpecBlock(SpecBlockReader& reader, const YAML::Node& node, const std::string& path,
                   const std::function<void(OptionsBinder&)>& bind,
                   const std::vector<const char*>& required);

// The usual `read` (SpecTermKind::read, SpriteConstraintKind::read) of a block that is its
// fields: a new T, whose fields `bind(keys, t)` binds, read by ReadSpecBlock.
template <typename T, typename Bind>
auto TermBlockReader(Bind bind, std::vector<const char*> required) {
  return [bind = std::move(bind), required = std::move(required)](
             SpecBlockReader& reader, const YAML::Node& node,
             const std::string& path) -> std::shared_ptr<const T> {
    auto term = std::make_shared<T>();
    ReadSpecBlock(
        reader, node, path, [&](OptionsBinder& keys) { bind(keys, *term); }, required);
    return term;
  };
}

// Called by each term's registration function; a second term of one key is an error.
void RegisterSpecTerm(SpecTermKind kind);
// Every term built in, by key.
std::vector<const SpecTermKind*> SpecTermKinds();

// A constraint of one sprite (an item `- KEY: {...}` of its `constraints:`) registered apart, as
// a term with a block of its own is: what it adds to a scene for its sprite. Its own files define
// `void Register<Name>SpriteConstraint()`, which calls RegisterSpriteConstraint, and one line in
// animate/CMakeLists.txt (spritestation_registrations) builds the call in. The judge measures only
// the typed ones, location, path and frames (AnimationSpec's fields, which the judge and the
// studio page read too); a registered one counts in the cost.
class SpriteConstraint {
 public:
  virtual ~SpriteConstraint() = default;
  // Adds its cost terms for sprite `sprite` of the problem (every sprite is added by then).
  virtual void AddTerms(const TransitionGraph& graph, Problem& problem, int sprite) const = 0;
  // The tags whose frames it reads (the banks are loaded with them marked: LoadBankGraph).
  virtual std::vector<std::string> Tags() const { return {}; }
};

struct SpriteConstraintKind {
  std::string key;  // its key in an item of `constraints:`
  // Reads its block at `path` (a mistake reported through `reader`, never thrown).
  std::function<std::shared_ptr<const SpriteConstraint>(
      SpecBlockReader& reader, const YAML::Node& node, const std::string& path)>
      read;
};

// Called by each constraint's registration function; a second constraint of one key, or one of
// the typed ones' keys, is an error.
void RegisterSpriteConstraint(SpriteConstraintKind kind);
// nullptr when no constraint of that key is registered.
const SpriteConstraintKind* FindSpriteConstraint(const std::string& key);
// The keys of every constraint: the typed ones and those registered.
std::vector<std::string> SpriteConstraintKeys();

}  // namespace ss
