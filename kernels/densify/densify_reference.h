// The CPU reference of densify_and_prune: the same decisions as the kernels (densify_math.h, bitwise), the
// same row order (each Gaussian's rows at its place, children after their parent's position), split
// samples from the same hash in double.
#pragma once

#include <vector>

#include "kernels/densify/densify.h"
#include "kernels/optim/training_state.h"

namespace litgs::kernels {

// `plane_distance`: [N] or empty (then params.flags must not ask for the plane prune).
TrainingState densify_reference(const TrainingState& in, const DensifyParams& params, bool reset_stats,
                                const std::vector<float>& plane_distance, DensifyReport* report);

// A split child's offset from its parent's mean in the parent's frame, in units of its scales (z, |z| <= 3).
void split_normals_reference(uint32_t seed, uint32_t step, uint32_t index, uint32_t child, double z[3]);

}  // namespace litgs::kernels
