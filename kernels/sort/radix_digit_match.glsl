// Ballot of the in-range lanes whose digit equals this lane's digit: one ballot per digit bit, no shared
// memory and no atomics (both are slow on CPU Vulkan drivers, where a subgroup is a SIMD register).
// Works for any subgroup size up to 128 (the ballot is a uvec4). Digits narrower than RADIX_DIGIT_BITS
// have zero high bits in every lane, so those ballots change nothing. Unrolled by hand: lavapipe caps the
// loop iterations of one invocation (all loops together) at 65535, so per-element loops are avoided.
#define RADIX_MATCH_BIT(b)                          \
  {                                                 \
    const bool bit = ((digit >> (b)) & 1u) != 0u;   \
    const uvec4 vote = subgroupBallot(bit);         \
    peers &= bit ? vote : ~vote;                    \
  }

uvec4 lanes_with_same_digit(uint digit, bool in_range) {
  uvec4 peers = subgroupBallot(in_range);
  RADIX_MATCH_BIT(0)
  RADIX_MATCH_BIT(1)
  RADIX_MATCH_BIT(2)
  RADIX_MATCH_BIT(3)
  RADIX_MATCH_BIT(4)
  RADIX_MATCH_BIT(5)
  RADIX_MATCH_BIT(6)
  RADIX_MATCH_BIT(7)
  return peers;
}
