#include "host/train/training_step.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "engine/sequence.h"

namespace litgs::host {
namespace {

using engine::DeviceArray;

// Loss slots of the small readback buffer.
constexpr uint32_t kSlotPhotometric = 0;  // loss, mean SSIM, mean L1
constexpr uint32_t kSlotGeometric = 3;    // loss, pixels that counted
constexpr uint32_t kLossSlots = 5;

}  // namespace

// Per-view device data that never changes: the target and, with the geometric loss, the LiDAR maps.
struct TrainingStep::ViewBuffers {
  std::unique_ptr<DeviceArray<float>> target;  // [H][W]
  std::unique_ptr<DeviceArray<float>> planes;  // [H][W][4] (n, n . P): GeometricLoss::pack_plane_targets
  uint32_t valid = 0;
};

TrainingStep::TrainingStep(engine::Context& ctx, const TrainingData& data, const PlanarMap* planes,
                           const TrainOptions& o, kernels::Rasterizer& rasterizer)
    : context_(&ctx),
      data_(&data),
      options_(&o),
      rasterizer_(&rasterizer),
      mcmc_options_(o.mcmc_options()),
      photometric_(ctx, 1,
                   [&] {
                     kernels::PhotometricLossOptions p;
                     p.lambda_ssim = static_cast<float>(o.lambda_ssim);
                     return p;
                   }()),
      geometric_(ctx),
      losses_(ctx, "train: losses", kLossSlots, engine::MemoryKind::kHostVisible),
      render_counters_(ctx, "train: render counters", SPLAT_COUNTER_COUNT, engine::MemoryKind::kHostVisible) {
  const uint32_t W = data.width, H = data.height;
  const bool geometric = o.lambda_geo > 0;
  if (geometric && !planes) throw std::invalid_argument("TrainingStep: lambda_geo > 0 needs a LiDAR map");
  photometric_.reserve(W, H);
  geometric_.reserve(W, H);
  views_.resize(data.views.size());
  for (uint32_t i = 0; i < data.views.size(); ++i) {
    ViewBuffers& v = views_[i];
    v.target = std::make_unique<DeviceArray<float>>(ctx, "train: view targets", size_t{W} * H);
    v.target->upload(data.views[i].image);
    if (geometric && !data.views[i].heldout) {
      const ViewPlaneMaps maps = project_planes(*planes, data.views[i].camera);
      const std::vector<float> targets =
          kernels::GeometricLoss::pack_plane_targets(maps.points, maps.normals);
      v.planes = std::make_unique<DeviceArray<float>>(ctx, "train: lidar plane targets", targets.size());
      v.planes->upload(targets);
      v.valid = maps.valid_count;
    }
  }
}

TrainingStep::~TrainingStep() = default;

void TrainingStep::run(kernels::TrainableGaussians& model, kernels::McmcStrategy* mcmc,
                       kernels::LevelModel* level, const kernels::LevelStep& level_step, uint32_t it,
                       uint32_t v, KernelTimes& times, TrainingCounters& counters) {
  const TrainOptions& o = *options_;
  const uint32_t W = data_->width, H = data_->height;
  const uint32_t step = it + 1;
  const bool geometric = o.lambda_geo > 0;
  kernels::Rasterizer& rasterizer = *rasterizer_;
  kernels::SplatCamera cam = data_->views[v].camera;
  cam.sh_degree = o.active_sh_degree(it);
  rasterizer.forward(model.gaussians(), cam);  // the iteration's one readback: the intersection count
  for (const auto& k : rasterizer.profile()) times[k.name] += k.ms;
  const auto out = rasterizer.device_outputs();
  const auto up = rasterizer.upstream_buffers();

  engine::Sequence s(*context_);
  // With a level model the loss sees g v x + o, and the level's backward turns its gradient into the
  // image's.
  const kernels::LevelGeometry level_geometry{W, H, 1, static_cast<float>(cam.cx),
                                              static_cast<float>(cam.cy)};
  if (level) level->record_apply(s, *out.image, v, level_geometry);
  photometric_.record(s, level ? level->leveled() : *out.image, views_[v].target->buffer(), W, H,
                      static_cast<float>(1.0 - o.lambda_geo), level ? level->grad_leveled() : *up.image,
                      losses_.buffer(), kSlotPhotometric);
  if (level) level->record_backward_step(s, *out.image, level_geometry, level_step, *up.image);
  if (geometric)
    geometric_.record(s, *out.depth, views_[v].planes->buffer(), W, H, static_cast<float>(cam.fx),
                      static_cast<float>(cam.fy), static_cast<float>(cam.cx), static_cast<float>(cam.cy),
                      views_[v].valid, static_cast<float>(o.lambda_geo),
                      static_cast<float>(o.geo_robust_scale_m), *up.depth, losses_.buffer(), kSlotGeometric);
  else
    s.fill(*up.depth, 0u, uint64_t{W} * H * sizeof(float));
  s.fill(*up.alpha, 0u, uint64_t{W} * H * sizeof(float));
  const auto grads = rasterizer.record_backward(s);
  // After the backward, so that its walks cut short are in this step's copy.
  s.copy(*out.counters, render_counters_.buffer(), SPLAT_COUNTER_COUNT * sizeof(uint32_t));
  if (!mcmc && step < o.refine_until()) model.record_accumulate_stats(s, grads, *out.rects, cam);
  kernels::LearningRates lr =
      model.adam_options().rates(it, o.iterations, static_cast<float>(data_->scene_extent_m));
  for (float* r : {&lr.means, &lr.log_scales, &lr.quats, &lr.opacity_logits, &lr.sh_dc, &lr.sh_rest})
    *r *= o.lr_scale;
  // One fused pass: the parameters' gradients (with MCMC's regularizers) and their Adam step.
  const kernels::TrainableGaussians::FusedStep fused{
      out.rects, cam,
      mcmc ? kernels::McmcStrategy::regularization_weights(mcmc_options_, static_cast<uint32_t>(model.size()))
           : kernels::RegularizationWeights{}};
  model.record_adam_step(s, grads, lr, step, &fused);
  if (mcmc) mcmc->record_noise(s, model, mcmc_options_, lr.means, step);
  s.submit_and_wait();
  for (const auto& k : s.profile()) times[k.name] += k.ms;
  const std::vector<uint32_t> c = render_counters_.download();  // host-visible: written by this submit
  counters.culled_nonfinite += c[SPLAT_COUNTER_CULLED_NONFINITE];
  const uint64_t walks_cut =
      uint64_t{c[SPLAT_COUNTER_FORWARD_WALKS_CUT]} + c[SPLAT_COUNTER_BACKWARD_WALKS_CUT];
  counters.walks_cut_short += walks_cut - walks_cut_seen_;
  walks_cut_seen_ = walks_cut;
}

StepLosses TrainingStep::last_losses() const {
  const TrainOptions& o = *options_;
  const bool geometric = o.lambda_geo > 0;
  const auto l = losses_.download();  // host-visible: written by the last step's submit
  StepLosses r;
  r.total = (1.0 - o.lambda_geo) * l[kSlotPhotometric] + (geometric ? o.lambda_geo * l[kSlotGeometric] : 0.0);
  r.photometric = l[kSlotPhotometric];
  r.geometric_rms_m = geometric ? std::sqrt(std::max(0.0, static_cast<double>(l[kSlotGeometric])))
                                : std::numeric_limits<double>::quiet_NaN();
  return r;
}

}  // namespace litgs::host
