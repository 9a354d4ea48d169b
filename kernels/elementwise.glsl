// Element-wise kernels (kernels/elementwise.h): ELEMENTWISE_GROUP_SIZE-wide workgroups in the grid that
// elementwise_groups() dispatches (one row while the groups fit in 65535, else several). Every element-wise
// shader takes its element from elementwise_index() and keeps its own `if (i >= count) return;`: the grid is
// rounded up to whole workgroups and rows.
#include "limits.h"

layout(local_size_x = ELEMENTWISE_GROUP_SIZE) in;

// The flat element index: row-major over the grid's groups, then the invocation within its group.
uint elementwise_index() {
  return (gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x) * uint(ELEMENTWISE_GROUP_SIZE) +
         gl_LocalInvocationID.x;
}

// Bitwise: fast-math may fold x == x.
bool finite_bits(float x) { return (floatBitsToUint(x) & 0x7f800000u) != 0x7f800000u; }
