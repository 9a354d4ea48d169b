// A model shrunk to a smaller budget: the rows of its most opaque Gaussians, each with its Adam moments and
// statistics. A budget growth that rolls a doubling back uses it (host/train/budget_growth.h); opacity is
// what MCMC itself ranks Gaussians by when it relocates the dead ones.
#pragma once

#include <cstddef>

#include "kernels/optim/training_state.h"

namespace litgs::host {

// The `count` rows of `state` with the largest opacity logits (ties: the lower row first), in their original
// order; `state` itself when it has at most `count` rows. std::invalid_argument for a state whose arrays
// disagree with its row count.
kernels::TrainingState keep_most_opaque(const kernels::TrainingState& state, size_t count);

}  // namespace litgs::host
