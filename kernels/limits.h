// Limits every kernel respects, shared by C++ and GLSL.
#ifndef LITGS_KERNELS_LIMITS_H
#define LITGS_KERNELS_LIMITS_H

// lavapipe (llvmpipe) stops a shader invocation's loops after 65535 iterations in total, silently, to guard
// against infinite loops. Kernels that walk a block in subgroup-wide batches therefore cap the batches per
// workgroup well below that, leaving room for their other loops.
#define MAX_BATCHES_PER_WORKGROUP 32768

#endif
