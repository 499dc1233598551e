#pragma once
// SplitMix64 (Steele, Lea & Flood, "Fast splittable pseudorandom number generators", 2014):
// a tiny, fast generator with a 64-bit state. Used wherever randomness is needed (RANSAC
// sampling, synthetic scenes, vocabulary-tree training) so that a seed fully determines the
// result on every platform and standard library (std::*_distribution output is
// implementation-defined).
#include <cmath>
#include <cstdint>

namespace reconar {

class SplitMix64 {
 public:
  explicit SplitMix64(uint64_t seed) : state_(seed) {}

  uint64_t Next() {
    uint64_t z = (state_ += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
  }

  // Uniform in [0, n) for n > 0; the modulo bias is below n / 2^64, negligible here.
  uint32_t UniformInt(uint32_t n) { return static_cast<uint32_t>(Next() % n); }

  // Uniform in [0, 1) with 53 random bits.
  double Uniform01() { return static_cast<double>(Next() >> 11) * 0x1.0p-53; }

  double Uniform(double lo, double hi) { return lo + (hi - lo) * Uniform01(); }

  // Standard normal by the Box-Muller transform (one of the pair is discarded for simplicity).
  double Gaussian() {
    double u1 = Uniform01();
    while (u1 <= 0.0) u1 = Uniform01();
    const double u2 = Uniform01();
    return std::sqrt(-2.0 * std::log(u1)) * std::cos(6.283185307179586 * u2);
  }

 private:
  uint64_t state_;
};

}  // namespace reconar
