// The animation spec (animate/spec.h): YAML with windows, counts and constraints, read as a
// station reads one a client sends, and, when it reads, the problem built over a small bank
// (Scene::Load: the cost terms, the frame sets), as `animate` and the studio's jobs do. Every
// number that sizes that work is bounded: run under -rss_limit_mb=1024 (issue 39).
#include <filesystem>

#include "animate/scene.h"
#include "animate/spec.h"
#include "core/log.h"
#include "tests/animate/animate_test_bank.h"
#include "tests/fuzz/fuzz_support.h"

namespace {

// The walker bank and a virtual camera, written once: a spec may name them as `walker.ssbank`
// and `virtual.cameramodel`; anything outside the folder is refused unopened.
const ss::SpecFileRules& Rules() {
  static const ss::SpecFileRules rules = [] {
    ss::SetLogLevel("warn");  // the bank's load says its size at info, each input
    const std::string& dir = ss::fuzz::ScratchDir();
    ss::testing::WalkerBank::Write(dir + "/walker.ssbank");
    ss::testing::LookAtCamera(320, 240, 300, {0, -4, 3}, {0, 0, 0})
        .Write(dir + "/virtual.cameramodel");
    ss::SpecFileRules r;
    r.base_dir = dir;
    r.roots = {dir};
    return r;
  }();
  return rules;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const ss::SpecFileRules& rules = Rules();
  return ss::fuzz::Expect([&] {
    ss::AnimationSpec spec = ss::ParseAnimationSpec(ss::fuzz::Text(data, size), "fuzz.yaml", rules);
    (void)ss::Scene::Load(std::move(spec));
  });
}
