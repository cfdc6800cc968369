// Reproducible random numbers for the simulator.
//
// Every random process (one chip's gyro noise, one module's vibration, ...) has
// its own stream, keyed by the seed and a name ("left-C1/gyro/arw"). So the
// same seed gives the same bytes on every platform and thread count, and
// switching one effect off leaves every other effect's draws unchanged (an
// error budget compares like with like). The generator is xoshiro256** seeded
// through splitmix64; normals by the Box-Muller transform (no std:: distributions,
// whose output differs between standard libraries).
#pragma once

#include <cmath>
#include <cstdint>
#include <string_view>

namespace wheelins::sim {

class Rng {
 public:
  Rng(std::uint64_t seed, std::string_view stream) {
    std::uint64_t h = 0xcbf29ce484222325ull;  // FNV-1a of the stream name
    for (unsigned char ch : stream) h = (h ^ ch) * 0x100000001b3ull;
    std::uint64_t x = seed ^ (h * 0x9E3779B97F4A7C15ull);
    for (auto& w : s_) w = splitmix(x);
  }
  std::uint64_t next_u64() {
    const std::uint64_t result = rotl(s_[1] * 5, 7) * 9;
    const std::uint64_t t = s_[1] << 17;
    s_[2] ^= s_[0];
    s_[3] ^= s_[1];
    s_[1] ^= s_[2];
    s_[0] ^= s_[3];
    s_[2] ^= t;
    s_[3] = rotl(s_[3], 45);
    return result;
  }
  /// Uniform in (0, 1).
  double uniform() { return (static_cast<double>(next_u64() >> 11) + 0.5) * 0x1.0p-53; }
  double uniform(double a, double b) { return a + (b - a) * uniform(); }
  /// Standard normal.
  double normal() {
    if (has_spare_) {
      has_spare_ = false;
      return spare_;
    }
    const double r = std::sqrt(-2.0 * std::log(uniform()));
    const double a = 6.283185307179586477 * uniform();
    spare_ = r * std::sin(a);
    has_spare_ = true;
    return r * std::cos(a);
  }
  double normal(double sigma) { return sigma * normal(); }

 private:
  static std::uint64_t rotl(std::uint64_t x, int k) { return (x << k) | (x >> (64 - k)); }
  static std::uint64_t splitmix(std::uint64_t& x) {
    std::uint64_t z = (x += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
  }
  std::uint64_t s_[4];
  double spare_ = 0.0;
  bool has_spare_ = false;
};

}  // namespace wheelins::sim
