#include "host/synth/rng.h"

#include <cmath>
#include <numbers>

namespace litgs::host::synth {

uint64_t mix64(uint64_t x) {
  x += 0x9e3779b97f4a7c15ull;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ull;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebull;
  return x ^ (x >> 31);
}

uint64_t hash_combine(uint64_t a, uint64_t b) {
  return mix64(mix64(a) ^ (b + 0x632be59bd9b4e019ull));
}

// 53 random bits: every double in [0, 1) this can return is exactly representable.
static double to_unit(uint64_t x) {
  return static_cast<double>(x >> 11) * 0x1.0p-53;
}

double hash_uniform(uint64_t key) {
  return to_unit(mix64(key));
}

double hash_normal(uint64_t key) {
  // 1 - u keeps the logarithm's argument in (0, 1].
  const double u1 = 1.0 - to_unit(mix64(key));
  const double u2 = to_unit(mix64(key ^ 0xd1b54a32d192ed03ull));
  return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * std::numbers::pi * u2);
}

uint64_t Rng::next_u64() {
  state_ += 0x9e3779b97f4a7c15ull;
  uint64_t z = state_;
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
  return z ^ (z >> 31);
}

double Rng::uniform() {
  return to_unit(next_u64());
}

double Rng::uniform(double a, double b) {
  return a + (b - a) * uniform();
}

int Rng::uniform_int(int lo, int hi) {
  const uint64_t span = static_cast<uint64_t>(hi - lo) + 1;
  return lo + static_cast<int>(next_u64() % span);
}

double Rng::normal() {
  const double u1 = 1.0 - uniform();
  const double u2 = uniform();
  return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * std::numbers::pi * u2);
}

}  // namespace litgs::host::synth
