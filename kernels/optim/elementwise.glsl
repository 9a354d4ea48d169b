// Element-wise kernels over more than 65535 workgroups: the host dispatches a 2D grid of
// ELEMENTWISE_GROUP_SIZE-wide groups (x at most 65535); this is the flat element index.
layout(local_size_x = ELEMENTWISE_GROUP_SIZE) in;

uint elementwise_index() {
  return (gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x) * uint(ELEMENTWISE_GROUP_SIZE) +
         gl_LocalInvocationID.x;
}

// Bitwise: fast-math may fold x == x.
bool finite_bits(float x) { return (floatBitsToUint(x) & 0x7f800000u) != 0x7f800000u; }
