#pragma once
// Deterministic randomness for the synthetic studio. Everything derives from
// std::mt19937_64 (whose output the standard fixes) through hand-written
// distributions, so a seed gives the same session on every platform.
#include <cstdint>
#include <random>
#include <string_view>

namespace ss::synth {

// Mixes a value into a hash (splitmix64 finalizer); used to derive sub-seeds.
uint64_t Mix(uint64_t hash, uint64_t value);
// A sub-seed for one named stream: Mix of `seed` with the name's bytes and `index`.
uint64_t StreamSeed(uint64_t seed, std::string_view name, uint64_t index = 0);

class Rng {
 public:
  explicit Rng(uint64_t seed) : engine_(seed) {}
  uint64_t Bits() { return engine_(); }
  double Uniform();  // [0, 1), 53 bits
  double Uniform(double lo, double hi) { return lo + (hi - lo) * Uniform(); }
  int UniformInt(int lo, int hi);  // [lo, hi] inclusive
  bool Chance(double probability) { return Uniform() < probability; }
  double Normal();  // standard normal, Box-Muller
  double Normal(double mean, double sigma) { return mean + sigma * Normal(); }

 private:
  std::mt19937_64 engine_;
  bool has_spare_ = false;
  double spare_ = 0.0;
};

// Smooth value noise in [-1, 1] at integer-lattice frequency 1, seeded.
double ValueNoise2(uint64_t seed, double x, double y);
double ValueNoise3(uint64_t seed, double x, double y, double z);
// Fractal sums of `octaves` octaves (gain 0.5, lacunarity 2), roughly in [-1, 1].
double Fbm2(uint64_t seed, double x, double y, int octaves);
double Fbm3(uint64_t seed, double x, double y, double z, int octaves);

}  // namespace ss::synth
