#pragma once
// SS_TARGET_CLONES("avx2", "default"): GCC's function multi-versioning, one body compiled per
// instruction set and the best picked at load time by an ifunc resolver. Under ThreadSanitizer
// (SPRITESTATION_SANITIZE=tsan) the resolver is instrumented and runs during relocation, before
// the sanitizer's runtime is up, and the executable crashes before main; there the default body
// alone is compiled.
#if defined(__SANITIZE_THREAD__)
#define SS_TARGET_CLONES(...)
#else
#define SS_TARGET_CLONES(...) __attribute__((target_clones(__VA_ARGS__)))
#endif
