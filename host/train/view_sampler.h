// The order in which training views are visited: each epoch all of them, without replacement, in a new random
// order. Its state (the epoch's order, the position in it, the generator) goes into checkpoints, so that a
// resumed run visits the same views as an uninterrupted one.
#pragma once

#include <algorithm>
#include <cstdint>
#include <random>
#include <sstream>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "host/train/checkpoint.h"

namespace litgs::host {

class ViewSampler {
 public:
  ViewSampler(std::vector<uint32_t> pool, uint32_t seed) : pool_(std::move(pool)), rng_(seed) { reshuffle(); }
  // Visits `pool` from now on, in a new random order (a growing budget's validation views rejoin training).
  void set_pool(std::vector<uint32_t> pool) {
    pool_ = std::move(pool);
    reshuffle();
  }
  uint32_t next() {
    if (position_ >= order_.size()) reshuffle();
    return order_[position_++];
  }
  void save(Checkpoint& c) const {
    c.view_order = order_;
    c.order_position = static_cast<uint32_t>(position_);
    std::ostringstream s;
    s << rng_;
    c.rng_state = s.str();
  }
  // Throws std::invalid_argument when the checkpoint's order is not a permutation of this pool (another
  // scene, or another hold-out split) or its generator state does not parse.
  void restore(const Checkpoint& c) {
    std::vector<uint32_t> a = c.view_order, b = pool_;
    std::sort(a.begin(), a.end());
    std::sort(b.begin(), b.end());
    if (a != b)
      throw std::invalid_argument("the checkpoint's view order (" + std::to_string(c.view_order.size()) +
                                  " views) is not an order of this run's " + std::to_string(pool_.size()) +
                                  " training views");
    std::istringstream s(c.rng_state);
    std::mt19937 rng;
    s >> rng;
    if (!s) throw std::invalid_argument("the checkpoint's random generator state does not parse");
    order_ = c.view_order;
    position_ = c.order_position;
    rng_ = rng;
  }

 private:
  void reshuffle() {
    order_ = pool_;
    std::shuffle(order_.begin(), order_.end(), rng_);
    position_ = 0;
  }
  std::vector<uint32_t> pool_, order_;
  size_t position_ = 0;
  std::mt19937 rng_;
};

}  // namespace litgs::host
