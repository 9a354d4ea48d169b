#include "host/train/shrink_model.h"

#include <algorithm>
#include <numeric>
#include <vector>

namespace litgs::host {
namespace {

// The kept rows of one per-row array (width values per row); an empty array stays empty.
template <class T>
std::vector<T> rows_of(const std::vector<T>& v, size_t rows, const std::vector<size_t>& keep) {
  if (v.empty()) return v;
  const size_t width = v.size() / rows;
  std::vector<T> out;
  out.reserve(keep.size() * width);
  for (size_t r : keep) out.insert(out.end(), v.begin() + r * width, v.begin() + (r + 1) * width);
  return out;
}

}  // namespace

kernels::TrainingState keep_most_opaque(const kernels::TrainingState& state, size_t count) {
  state.check();
  const size_t n = state.size();
  if (n <= count) return state;
  std::vector<size_t> order(n);
  std::iota(order.begin(), order.end(), size_t{0});
  const std::vector<float>& opacity = state.model.opacity_logits;
  std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) { return opacity[a] > opacity[b]; });
  order.resize(count);
  std::sort(order.begin(), order.end());

  kernels::TrainingState out = state;
  for (uint32_t g = 0; g < kernels::kParamGroupCount; ++g) {
    kernels::group_values(out.model, g) = rows_of(kernels::group_values(state.model, g), n, order);
    out.exp_avg[g] = rows_of(state.exp_avg[g], n, order);
    out.exp_avg_sq[g] = rows_of(state.exp_avg_sq[g], n, order);
  }
  out.grad_accum = rows_of(state.grad_accum, n, order);
  out.denom = rows_of(state.denom, n, order);
  out.max_radius = rows_of(state.max_radius, n, order);
  out.check();
  return out;
}

}  // namespace litgs::host
