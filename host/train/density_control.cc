#include "host/train/density_control.h"

#include <algorithm>
#include <vector>

#include "engine/sequence.h"
#include "kernels/device_growth.h"

namespace litgs::host {

DensityControl::DensityControl(engine::Context& ctx, const TrainOptions& o, const PlanarMap* planes,
                               float scene_extent_m)
    : context_(&ctx), options_(&o), extent_(scene_extent_m), mcmc_(o.mcmc_options()) {
  densify_.grad_threshold = o.densify_grad_threshold;
  densify_.max_gaussians = o.max_gaussians;
  densify_.opacity_reset_interval = o.opacity_reset_every;
  densify_.seed = o.seed;
  if (o.lambda_geo > 0 && planes && o.plane_prune_k > 0)
    plane_index_ = std::make_unique<PlaneDistance>(*planes);
}

DensityControl::~DensityControl() = default;

void DensityControl::after_step(kernels::TrainableGaussians& model, kernels::McmcStrategy* mcmc,
                                uint32_t step, TrainingCounters& counters) {
  const TrainOptions& o = *options_;
  const uint32_t until = o.refine_until();
  if (step > o.densify_from && step < until && step % o.densify_every == 0) {
    // The method's geometric outlier removal: Gaussians far from their LiDAR plane, beyond a robust bound of
    // all distances, are pruned with the others.
    const engine::Buffer* plane_distance = nullptr;
    kernels::DensifyOptions step_options = densify_;
    if (plane_index_) {
      // Only the means come back to the host, and the distance buffer is reused while it is large enough.
      const engine::DeviceArray<float>& means = model.gaussians().means;
      const std::vector<float> d = plane_index_->distances(means.download(0, 3 * model.size()));
      kernels::grow(*context_, plane_distances_, d.size(), "train: plane distances");
      plane_distances_->upload(d);
      plane_distance = &plane_distances_->buffer();
      step_options.max_plane_distance_m = PlaneDistance::robust_bound(d, o.plane_prune_k);
    }
    if (mcmc) {
      kernels::McmcOptions step_mcmc = mcmc_;
      step_mcmc.max_plane_distance_m = step_options.max_plane_distance_m;
      const kernels::McmcReport m = mcmc->relocate_and_grow(model, step_mcmc, step, plane_distance);
      counters.pruned_plane += m.dead_plane;
      counters.pruned_nonfinite += m.dead_nonfinite;
    } else {
      const kernels::DensifyReport d = model.densify_and_prune(step_options, extent_, step, plane_distance);
      counters.pruned_plane += d.pruned_plane;
      counters.pruned_nonfinite += d.pruned_nonfinite;
      counters.densify_capped += d.capped;
    }
  }
  if (!mcmc && step < until && step % o.opacity_reset_every == 0) {
    engine::Sequence r(*context_);
    model.record_reset_opacity(r);
    r.submit_and_wait();
  }
}

}  // namespace litgs::host
