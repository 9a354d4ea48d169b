// Limits every kernel respects, shared by C++ and GLSL.
#ifndef LITGS_KERNELS_LIMITS_H
#define LITGS_KERNELS_LIMITS_H

// lavapipe (llvmpipe) stops a shader invocation's loops after 65535 iterations in total, silently, to guard
// against infinite loops. Kernels that walk a block in subgroup-wide batches therefore cap the batches per
// workgroup well below that, leaving room for their other loops.
#define MAX_BATCHES_PER_WORKGROUP 32768

// Element-wise kernels (one invocation per Gaussian, intersection or pixel) use workgroups of this
// size: 16.7M elements fit in the 65535 workgroups every device allows in x, and more take rows
// (kernels/elementwise.h).
#define ELEMENTWISE_GROUP_SIZE 256

// The rasterize kernels walk a tile's list in passes (kernels/splat/splat_shared.h) and size each pass so
// that an invocation spends at most this many loop iterations in it: three quarters of lavapipe's limit, the
// rest being margin for the bound's uncertainty (Rasterizer: loops per chunk of entries) and the kernel's
// other loops.
#define RASTERIZE_PASS_LOOP_BUDGET 49152

#endif
