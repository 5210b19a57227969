#pragma once
// Random numbers that are the same on every platform for a given seed.
//
// std::mt19937_64's output sequence is fixed by the C++ standard, but the
// std::*_distribution classes are implementation-defined (libstdc++ and
// libc++ give different normals from the same engine). The simulator's
// frames must be reproducible from a seed, so the distributions are written
// out here: 53-bit uniforms from the engine's output and Box-Muller normals.
#include <cmath>
#include <cstdint>
#include <random>

namespace tofguard::sim {

// SplitMix64 finaliser: turns (seed, stream) into well-mixed seeds for
// independent streams (e.g. one per frame).
inline uint64_t mix_seed(uint64_t seed, uint64_t stream) {
  uint64_t z = seed + 0x9e3779b97f4a7c15ULL * (stream + 1);
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}

class DeterministicRandom {
 public:
  explicit DeterministicRandom(uint64_t seed) : engine_(seed) {}

  // Uniform in [0, 1), 53 random bits.
  double uniform() { return static_cast<double>(engine_() >> 11) * 0x1.0p-53; }

  // Standard normal (mean 0, standard deviation 1), Box-Muller: two
  // uniforms give two independent normals; the second is kept for the next
  // call.
  double normal() {
    if (has_spare_) {
      has_spare_ = false;
      return spare_;
    }
    const double u1 = 1.0 - uniform();  // (0, 1]: log(u1) is finite
    const double u2 = uniform();
    const double radius = std::sqrt(-2.0 * std::log(u1));
    const double angle = 2.0 * M_PI * u2;
    spare_ = radius * std::sin(angle);
    has_spare_ = true;
    return radius * std::cos(angle);
  }

 private:
  std::mt19937_64 engine_;
  bool has_spare_ = false;
  double spare_ = 0;
};

}  // namespace tofguard::sim
