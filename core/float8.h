#pragma once
// Eight floats as one GCC vector (one AVX register where a SS_TARGET_CLONES clone is built for
// AVX, two SSE registers otherwise), with unaligned loads and stores. The kernels that use them
// (animate/skeleton's cost rows and DP row step) call them only from inline code: a 32-byte
// vector argument never crosses a library boundary.
#include <cstring>

#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wpsabi"

namespace ss::float8 {

typedef float v8f __attribute__((vector_size(32)));

inline v8f Load(const float* p) {
  v8f v;
  std::memcpy(&v, p, sizeof(v));
  return v;
}
inline void Store(float* p, v8f v) { std::memcpy(p, &v, sizeof(v)); }

}  // namespace ss::float8

#pragma GCC diagnostic pop
