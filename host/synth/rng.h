// Deterministic random numbers for the synthetic generator. Our own generator (splitmix64) and our own
// normal transform: std::normal_distribution is implementation-defined, and a seed must give the same scene
// bytes with every standard library.
#pragma once

#include <cstdint>

namespace litgs::host::synth {

// A 64-bit finalizer (splitmix64's): a good hash of one integer.
uint64_t mix64(uint64_t x);
// Hash of an ordered pair, for keys such as (seed, stream) or (frame, pixel).
uint64_t hash_combine(uint64_t a, uint64_t b);
// Uniform in [0, 1) and standard normal, as pure functions of a key (noise that needs no generator state,
// so rows of an image can be filled by any thread in any order).
double hash_uniform(uint64_t key);
double hash_normal(uint64_t key);

// Named streams: each simulated quantity draws from its own stream, so adding draws to one (more anchors)
// never changes another (the LiDAR noise).
enum class Stream : uint64_t {
  kLidar = 1,
  kImu,
  kPoses,
  kAnchors,
  kThermal,
  kNuc,
  kTexture,
  kRig,
  kCalibration,
};

class Rng {
 public:
  explicit Rng(uint64_t seed) : state_(mix64(seed)) {}
  Rng(uint64_t seed, Stream stream, uint64_t index = 0)
      : state_(hash_combine(hash_combine(seed, static_cast<uint64_t>(stream)), index)) {}

  uint64_t next_u64();
  double uniform();                    // [0, 1)
  double uniform(double a, double b);  // [a, b)
  int uniform_int(int lo, int hi);     // [lo, hi], hi >= lo
  double normal();                     // standard normal (Box-Muller)

 private:
  uint64_t state_;
};

}  // namespace litgs::host::synth
