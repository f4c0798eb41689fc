#include "synth/random.h"

#include <cmath>

namespace ss::synth {

uint64_t Mix(uint64_t hash, uint64_t value) {
  uint64_t z = hash ^ (value + 0x9e3779b97f4a7c15ULL + (hash << 6) + (hash >> 2));
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}

uint64_t StreamSeed(uint64_t seed, std::string_view name, uint64_t index) {
  uint64_t h = Mix(0x5353u, seed);
  for (char c : name) h = Mix(h, static_cast<unsigned char>(c));
  return Mix(h, index);
}

double Rng::Uniform() { return static_cast<double>(engine_() >> 11) * (1.0 / 9007199254740992.0); }

int Rng::UniformInt(int lo, int hi) {
  const uint64_t span = static_cast<uint64_t>(hi - lo) + 1;
  return lo + static_cast<int>(engine_() % span);
}

double Rng::Normal() {
  if (has_spare_) {
    has_spare_ = false;
    return spare_;
  }
  double u1 = 0.0;
  do {
    u1 = Uniform();
  } while (u1 <= 1e-300);
  const double u2 = Uniform();
  const double r = std::sqrt(-2.0 * std::log(u1));
  const double a = 2.0 * M_PI * u2;
  spare_ = r * std::sin(a);
  has_spare_ = true;
  return r * std::cos(a);
}

namespace {

inline double Lattice(uint64_t seed, int64_t x, int64_t y, int64_t z) {
  uint64_t h = Mix(seed, static_cast<uint64_t>(x));
  h = Mix(h, static_cast<uint64_t>(y));
  h = Mix(h, static_cast<uint64_t>(z));
  return static_cast<double>(h >> 11) * (2.0 / 9007199254740992.0) - 1.0;
}

inline double Fade(double t) { return t * t * (3.0 - 2.0 * t); }

}  // namespace

double ValueNoise2(uint64_t seed, double x, double y) {
  const double fx = std::floor(x), fy = std::floor(y);
  const auto ix = static_cast<int64_t>(fx), iy = static_cast<int64_t>(fy);
  const double tx = Fade(x - fx), ty = Fade(y - fy);
  const double a = Lattice(seed, ix, iy, 0), b = Lattice(seed, ix + 1, iy, 0);
  const double c = Lattice(seed, ix, iy + 1, 0), d = Lattice(seed, ix + 1, iy + 1, 0);
  return (a + (b - a) * tx) + ((c + (d - c) * tx) - (a + (b - a) * tx)) * ty;
}

double ValueNoise3(uint64_t seed, double x, double y, double z) {
  const double fx = std::floor(x), fy = std::floor(y), fz = std::floor(z);
  const auto ix = static_cast<int64_t>(fx), iy = static_cast<int64_t>(fy),
             iz = static_cast<int64_t>(fz);
  const double tx = Fade(x - fx), ty = Fade(y - fy), tz = Fade(z - fz);
  double v[2];
  for (int k = 0; k < 2; ++k) {
    const double a = Lattice(seed, ix, iy, iz + k), b = Lattice(seed, ix + 1, iy, iz + k);
    const double c = Lattice(seed, ix, iy + 1, iz + k), d = Lattice(seed, ix + 1, iy + 1, iz + k);
    const double ab = a + (b - a) * tx, cd = c + (d - c) * tx;
    v[k] = ab + (cd - ab) * ty;
  }
  return v[0] + (v[1] - v[0]) * tz;
}

double Fbm2(uint64_t seed, double x, double y, int octaves) {
  double sum = 0.0, amp = 0.5, norm = 0.0;
  for (int o = 0; o < octaves; ++o) {
    sum += amp * ValueNoise2(Mix(seed, o), x, y);
    norm += amp;
    amp *= 0.5;
    x *= 2.0;
    y *= 2.0;
  }
  return sum / norm;
}

double Fbm3(uint64_t seed, double x, double y, double z, int octaves) {
  double sum = 0.0, amp = 0.5, norm = 0.0;
  for (int o = 0; o < octaves; ++o) {
    sum += amp * ValueNoise3(Mix(seed, o), x, y, z);
    norm += amp;
    amp *= 0.5;
    x *= 2.0;
    y *= 2.0;
    z *= 2.0;
  }
  return sum / norm;
}

}  // namespace ss::synth
