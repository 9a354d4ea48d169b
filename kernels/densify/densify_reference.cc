#include "kernels/densify/densify_reference.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "kernels/densify/densify_math.h"
#include "kernels/splat/splat_math.h"

namespace litgs::kernels {

void split_normals_reference(uint32_t seed, uint32_t step, uint32_t index, uint32_t child, double z[3]) {
  for (uint32_t a = 0; a < 3; ++a) {
    const double u1 = densify_math::split_uniform(seed, step, index, child, a, 0u);
    const double u2 = densify_math::split_uniform(seed, step, index, child, a, 1u);
    z[a] = std::clamp(std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * M_PI * u2), -3.0, 3.0);
  }
}

TrainingState densify_reference(const TrainingState& in, const DensifyParams& p, bool reset_stats,
                                const std::vector<float>& plane_distance, DensifyReport* report) {
  in.check();
  const size_t n = in.size();
  if ((p.flags & DENSIFY_FLAG_PLANE_PRUNE) && plane_distance.size() != n)
    throw std::invalid_argument("densify_reference: plane prune without one distance per Gaussian");
  const uint32_t sv = in.model.sh_coeffs() * in.model.channels;
  const uint32_t widths[kParamGroupCount] = {3, 3, 4, 1, sv};
  TrainingState out;
  out.model.channels = in.model.channels;
  out.model.sh_degree = in.model.sh_degree;
  DensifyReport r;
  r.before = static_cast<uint32_t>(n);

  auto input = [&](size_t i) {
    densify_math::DensifyInput g{};
    bool finite = true;
    float max_log_scale = in.model.log_scales[3 * i];
    for (int a = 0; a < 3; ++a) {
      finite =
          finite && std::isfinite(in.model.means[3 * i + a]) && std::isfinite(in.model.log_scales[3 * i + a]);
      max_log_scale = std::max(max_log_scale, in.model.log_scales[3 * i + a]);
    }
    for (int a = 0; a < 4; ++a) finite = finite && std::isfinite(in.model.quats[4 * i + a]);
    for (uint32_t k = 0; k < sv; ++k) finite = finite && std::isfinite(in.model.sh[i * sv + k]);
    g.opacity_logit = in.model.opacity_logits[i];
    g.finite = finite && std::isfinite(g.opacity_logit);
    g.max_log_scale = max_log_scale;
    g.grad_accum = in.grad_accum[i];
    g.denom = in.denom[i];
    g.max_radius = in.max_radius[i];
    g.plane_distance = (p.flags & DENSIFY_FLAG_PLANE_PRUNE) ? plane_distance[i] : 0.0f;
    return g;
  };

  // Appends row i of every array; `fresh` zeroes moments (and statistics), `child` >= 0 samples a split
  // child.
  auto append = [&](size_t i, bool fresh, int child) {
    for (uint32_t g = 0; g < kParamGroupCount; ++g) {
      const auto& src = group_values(in.model, g);
      auto& dst = group_values(out.model, g);
      dst.insert(dst.end(), src.begin() + i * widths[g], src.begin() + (i + 1) * widths[g]);
      for (auto* m : {&out.exp_avg[g], &out.exp_avg_sq[g]}) {
        const auto& msrc = m == &out.exp_avg[g] ? in.exp_avg[g] : in.exp_avg_sq[g];
        if (fresh)
          m->insert(m->end(), widths[g], 0.0f);
        else
          m->insert(m->end(), msrc.begin() + i * widths[g], msrc.begin() + (i + 1) * widths[g]);
      }
    }
    const bool zero_stats = reset_stats || fresh;
    out.grad_accum.push_back(zero_stats ? 0.0f : in.grad_accum[i]);
    out.denom.push_back(zero_stats ? 0u : in.denom[i]);
    out.max_radius.push_back(zero_stats ? 0.0f : in.max_radius[i]);
    if (child < 0) return;
    using namespace splat_math;
    const dvec4 q(in.model.quats[4 * i], in.model.quats[4 * i + 1], in.model.quats[4 * i + 2],
                  in.model.quats[4 * i + 3]);
    const dmat3 R = rotation_from_unit_quat(unit_quat(q));
    double z[3];
    split_normals_reference(p.seed, p.step, static_cast<uint32_t>(i), static_cast<uint32_t>(child), z);
    dvec3 s;
    for (int a = 0; a < 3; ++a) s[a] = std::exp(double{in.model.log_scales[3 * i + a]}) * z[a];
    const dvec3 offset = R * s;
    const size_t row = out.model.opacity_logits.size() - 1;
    for (int a = 0; a < 3; ++a) {
      out.model.means[3 * row + a] = static_cast<float>(in.model.means[3 * i + a] + offset[a]);
      out.model.log_scales[3 * row + a] = in.model.log_scales[3 * i + a] - p.log_split_divisor;
    }
  };

  uint32_t rank = 0;
  auto count_reason = [&](uint32_t reason) {
    switch (reason) {
      case PRUNE_NONFINITE:
        ++r.pruned_nonfinite;
        break;
      case PRUNE_OPACITY:
        ++r.pruned_opacity;
        break;
      case PRUNE_PLANE:
        ++r.pruned_plane;
        break;
      case PRUNE_WORLD_SIZE:
        ++r.pruned_world_size;
        break;
      case PRUNE_SCREEN_SIZE:
        ++r.pruned_screen_size;
        break;
      default:
        break;
    }
  };
  for (size_t i = 0; i < n; ++i) {
    const densify_math::DensifyInput g = input(i);
    const bool candidate = densify_math::densify_candidate(p, g);
    const bool within = rank < p.budget;
    if (candidate) ++rank;
    uint32_t reason_a = 0, reason_b = 0;
    const uint32_t d = densify_math::densify_decision(p, g, within, reason_a, reason_b);
    const uint32_t kind = d & DENSIFY_KIND_MASK;
    if (candidate && !within) ++r.capped;
    if (kind == DENSIFY_KIND_CLONE) ++r.cloned;
    if (kind == DENSIFY_KIND_SPLIT) ++r.split;
    count_reason(reason_a);
    if (kind != DENSIFY_KIND_KEEP) count_reason(reason_b);
    const bool split = kind == DENSIFY_KIND_SPLIT;
    if (d & DENSIFY_SLOT_A) append(i, split, split ? 0 : -1);
    if (d & DENSIFY_SLOT_B) append(i, true, split ? 1 : -1);
  }
  r.after = static_cast<uint32_t>(out.model.opacity_logits.size());
  if (report) *report = r;
  return out;
}

}  // namespace litgs::kernels
