// Ballot of the in-range lanes whose digit equals this lane's digit: one ballot per digit bit, no shared
// memory and no atomics (both are slow on CPU Vulkan drivers, where a subgroup is a SIMD register).
// Digits narrower than RADIX_DIGIT_BITS have zero high bits in every lane, so those ballots change nothing.
// Unrolled by hand: lavapipe caps the loop iterations of one invocation (all loops together) at 65535.
//
// Subgroups of up to 32 lanes keep the ballot in one uint (SUBGROUP_SIZE is a specialization constant, so
// the other branch is folded away); larger subgroups use the full uvec4.
#define RADIX_MATCH_BIT(b, T, component)                               \
  {                                                                    \
    const bool bit = ((digit >> (b)) & 1u) != 0u;                      \
    const T vote = T(subgroupBallot(bit) component);                   \
    peers &= bit ? vote : ~vote;                                       \
  }
#define RADIX_MATCH_ALL_BITS(T, component) \
  RADIX_MATCH_BIT(0, T, component)         \
  RADIX_MATCH_BIT(1, T, component)         \
  RADIX_MATCH_BIT(2, T, component)         \
  RADIX_MATCH_BIT(3, T, component)         \
  RADIX_MATCH_BIT(4, T, component)         \
  RADIX_MATCH_BIT(5, T, component)         \
  RADIX_MATCH_BIT(6, T, component)         \
  RADIX_MATCH_BIT(7, T, component)

uvec4 lanes_with_same_digit(uint digit, bool in_range) {
  if (SUBGROUP_SIZE <= 32u) {
    uint peers = subgroupBallot(in_range).x;
    RADIX_MATCH_ALL_BITS(uint, .x)
    return uvec4(peers, 0u, 0u, 0u);
  }
  uvec4 peers = subgroupBallot(in_range);
  RADIX_MATCH_ALL_BITS(uvec4, )
  return peers;
}

// Position of this lane among its peers, their number, and whether it is the last of them.
uint peer_rank(uvec4 peers) {
  if (SUBGROUP_SIZE <= 32u) return bitCount(peers.x & gl_SubgroupLtMask.x);
  return subgroupBallotExclusiveBitCount(peers);
}
uint peer_count(uvec4 peers) {
  if (SUBGROUP_SIZE <= 32u) return bitCount(peers.x);
  return subgroupBallotBitCount(peers);
}
bool is_last_peer(uvec4 peers) {
  if (SUBGROUP_SIZE <= 32u) return uint(findMSB(peers.x)) == gl_SubgroupInvocationID;
  return subgroupBallotFindMSB(peers) == gl_SubgroupInvocationID;
}
