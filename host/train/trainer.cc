#include "host/train/trainer.h"

#include <algorithm>
#include <map>
#include <chrono>
#include <cmath>
#include <limits>
#include <memory>
#include <nlohmann/json.hpp>
#include <random>
#include <sstream>
#include <stdexcept>

#include "engine/buffer.h"
#include "engine/sequence.h"
#include "host/train/checkpoint.h"
#include "io/atomic_file.h"
#include "io/gaussian_ply.h"
#include "kernels/loss/geometric_loss.h"
#include "kernels/loss/loss_reference.h"
#include "kernels/loss/photometric_loss.h"
#include "kernels/mcmc/mcmc.h"
#include "kernels/optim/trainable_gaussians.h"
#include "kernels/splat/rasterizer.h"

namespace litgs::host {
namespace {

using engine::DeviceArray;
namespace fs = std::filesystem;

// Loss slots of the small readback buffer.
constexpr uint32_t kSlotPhotometric = 0;  // loss, mean SSIM, mean L1
constexpr uint32_t kSlotGeometric = 3;    // loss, pixels that counted
constexpr uint32_t kLossSlots = 5;

// Per-view device data that never changes: the target and, with the geometric loss, the LiDAR maps.
struct ViewBuffers {
  std::unique_ptr<DeviceArray<float>> target;   // [H][W]
  std::unique_ptr<DeviceArray<float>> points;   // [H][W][4]
  std::unique_ptr<DeviceArray<float>> normals;  // [H][W][4]
  uint32_t valid = 0;
};

// Views of one epoch in a random order, without replacement; a new order each epoch.
class ViewSampler {
 public:
  ViewSampler(std::vector<uint32_t> pool, uint32_t seed) : pool_(std::move(pool)), rng_(seed) { reshuffle(); }
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
  void restore(const Checkpoint& c) {
    order_ = c.view_order;
    position_ = c.order_position;
    std::istringstream s(c.rng_state);
    s >> rng_;
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

fs::path newest_checkpoint(const fs::path& dir) {
  fs::path best;
  uint32_t best_it = 0;
  if (!fs::is_directory(dir / "checkpoints")) return best;
  for (const auto& e : fs::directory_iterator(dir / "checkpoints")) {
    const std::string name = e.path().filename().string();
    if (name.rfind("iter_", 0) != 0 || e.path().extension() != ".ckpt") continue;
    const uint32_t it = static_cast<uint32_t>(std::stoul(name.substr(5)));
    if (best.empty() || it > best_it) best = e.path(), best_it = it;
  }
  return best;
}

nlohmann::json eval_json(const EvalResult& e) {
  nlohmann::json j = {{"iteration", e.iteration}, {"psnr_db", e.psnr_db}, {"ssim", e.ssim}};
  if (e.depth_plane_rmse_m >= 0) j["depth_plane_rmse_m"] = e.depth_plane_rmse_m;
  return j;
}

}  // namespace

void TrainOptions::check() const {
  auto bad = [](const std::string& what) { throw std::invalid_argument("TrainOptions." + what); };
  if (iterations == 0) bad("iterations must be positive");
  if (!(lambda_geo >= 0 && lambda_geo <= 1)) bad("lambda_geo must be in [0, 1]");
  if (!(lambda_ssim >= 0 && lambda_ssim <= 1)) bad("lambda_ssim must be in [0, 1]");
  if (!(geo_robust_scale_m >= 0) || !std::isfinite(geo_robust_scale_m))
    bad("geo_robust_scale_m must be finite and >= 0 (0: squared residuals)");
  if (sh_degree > 3) bad("sh_degree must be 0..3");
  if (!(plane_prune_k >= 0) || !std::isfinite(plane_prune_k)) bad("plane_prune_k must be >= 0 (0: no plane prune)");
  if (sh_degree_every == 0) bad("sh_degree_every must be positive");
  if (densify_every == 0) bad("densify_every must be positive");
  if (opacity_reset_every == 0) bad("opacity_reset_every must be positive");
  if (!(densify_grad_threshold > 0)) bad("densify_grad_threshold must be positive");
  if (max_gaussians == 0) bad("max_gaussians must be positive");
  if (!(lr_scale > 0) || !std::isfinite(lr_scale)) bad("lr_scale must be positive");
  if (strategy != "adc" && strategy != "mcmc") bad("strategy must be adc or mcmc, not '" + strategy + "'");
  if (strategy == "mcmc") mcmc_options().check();
}

kernels::McmcOptions TrainOptions::mcmc_options() const {
  kernels::McmcOptions m;
  m.max_gaussians = max_gaussians;
  m.growth = mcmc_growth;
  m.noise_lr = mcmc_noise_lr;
  m.opacity_reg = static_cast<float>(mcmc_opacity_reg * photometric_weight());
  m.scale_reg = static_cast<float>(mcmc_scale_reg * photometric_weight());
  m.seed = seed;
  return m;
}

TrainReport train(engine::Context& ctx, const TrainingData& data, const kernels::GaussianModel& initial,
                  const PlanarMap* planes, const TrainOptions& o, const fs::path& out_dir,
                  const std::function<void(const TrainProgress&)>& progress, const PlanarMap* gt_planes) {
  o.check();
  if (o.lambda_geo > 0 && !planes)
    throw std::invalid_argument("lambda_geo > 0 needs a LiDAR map (the scene has none); use --lambda-geo 0");
  std::vector<uint32_t> train_views, eval_views;
  for (uint32_t i = 0; i < data.views.size(); ++i) (data.views[i].heldout ? eval_views : train_views).push_back(i);
  if (train_views.empty()) throw std::invalid_argument("no training views (all held out)");
  fs::create_directories(out_dir);
  if (o.checkpoint_every > 0) fs::create_directories(out_dir / "checkpoints");
  const uint32_t W = data.width, H = data.height;
  const bool geometric = o.lambda_geo > 0;

  // Device state.
  kernels::RasterizerOptions ropt;
  ropt.deterministic = o.deterministic;
  ropt.depth_gradient_to_opacity = o.geo_gradient_to_opacity;
  kernels::Rasterizer rasterizer(ctx, 1, ropt);
  kernels::PhotometricLossOptions popt;
  popt.lambda_ssim = static_cast<float>(o.lambda_ssim);
  kernels::PhotometricLoss photometric(ctx, 1, popt);
  photometric.reserve(W, H);
  kernels::GeometricLoss geometric_loss(ctx);
  geometric_loss.reserve(W, H);
  DeviceArray<float> losses(ctx, "train: losses", kLossSlots, engine::MemoryKind::kHostVisible);
  std::vector<ViewBuffers> views(data.views.size());
  for (uint32_t i = 0; i < data.views.size(); ++i) {
    views[i].target = std::make_unique<DeviceArray<float>>(ctx, "train: target " + data.views[i].name, size_t{W} * H);
    views[i].target->upload(data.views[i].image);
    if (geometric && !data.views[i].heldout) {
      const ViewPlaneMaps maps = project_planes(*planes, data.views[i].camera);
      views[i].points = std::make_unique<DeviceArray<float>>(ctx, "train: lidar points", maps.points.size());
      views[i].normals = std::make_unique<DeviceArray<float>>(ctx, "train: lidar normals", maps.normals.size());
      views[i].points->upload(maps.points);
      views[i].normals->upload(maps.normals);
      views[i].valid = maps.valid_count;
    }
  }

  std::unique_ptr<kernels::TrainableGaussians> model;
  ViewSampler sampler(train_views, o.seed);
  uint32_t start = 0;
  if (o.resume) {
    const fs::path ckpt = newest_checkpoint(out_dir);
    if (ckpt.empty()) throw std::invalid_argument("--resume: no checkpoint in " + (out_dir / "checkpoints").string());
    const Checkpoint c = read_checkpoint(ckpt);
    model = std::make_unique<kernels::TrainableGaussians>(ctx, c.state);
    sampler.restore(c);
    start = c.iteration;
  } else {
    model = std::make_unique<kernels::TrainableGaussians>(ctx, initial);
  }
  const kernels::AdamOptions adam = model->adam_options();
  kernels::DensifyOptions dopt;
  dopt.grad_threshold = o.densify_grad_threshold;
  dopt.max_gaussians = o.max_gaussians;
  dopt.opacity_reset_interval = o.opacity_reset_every;
  dopt.seed = o.seed;
  const bool mcmc = o.strategy == "mcmc";
  const kernels::McmcOptions mopt = o.mcmc_options();
  std::unique_ptr<kernels::McmcStrategy> mcmc_strategy;
  if (mcmc) mcmc_strategy = std::make_unique<kernels::McmcStrategy>(ctx);
  // Refinement and opacity resets run while step < densify_until (3DGS), so never on the last iteration:
  // Gaussians split, relocated or made transparent there would reach the output unfitted.
  const uint32_t densify_until = std::min(o.densify_until, o.iterations);
  const float extent = static_cast<float>(data.scene_extent_m);
  std::unique_ptr<PlaneDistance> plane_index;
  if (geometric && o.plane_prune_k > 0) plane_index = std::make_unique<PlaneDistance>(*planes);
  std::unique_ptr<DeviceArray<float>> plane_distances;

  TrainReport report;
  auto evaluate = [&](uint32_t iteration) {
    EvalResult e;
    e.iteration = iteration;
    if (eval_views.empty()) return e;
    double plane_sq = 0;
    size_t plane_n = 0;
    for (uint32_t i : eval_views) {
      kernels::SplatCamera cam = data.views[i].camera;
      cam.sh_degree = std::min(o.sh_degree, iteration / o.sh_degree_every);
      rasterizer.forward(model->gaussians(), cam);
      const auto img = rasterizer.download_images();
      e.psnr_db += kernels::psnr(img.image, data.views[i].image);
      e.ssim += kernels::ssim_reference(img.image, data.views[i].image, 1, W, H);
      if (gt_planes) {
        // Point-to-plane residual of the rendered depth along each pixel's ray, where a true plane is seen
        // and the render is opaque enough to have a depth.
        const ViewPlaneMaps truth = project_planes(*gt_planes, cam);
        for (uint32_t y = 0; y < H; ++y)
          for (uint32_t x = 0; x < W; ++x) {
            const size_t p = size_t{y} * W + x;
            if (truth.points[4 * p + 3] != 1.0f || img.alpha[p] < 0.5f) continue;
            const double rx = (x + 0.5 - cam.cx) / cam.fx, ry = (y + 0.5 - cam.cy) / cam.fy, D = img.depth[p];
            const double r = truth.normals[4 * p] * (truth.points[4 * p] - D * rx) +
                             truth.normals[4 * p + 1] * (truth.points[4 * p + 1] - D * ry) +
                             truth.normals[4 * p + 2] * (truth.points[4 * p + 2] - D);
            plane_sq += r * r;
            ++plane_n;
          }
      }
    }
    e.psnr_db /= static_cast<double>(eval_views.size());
    e.ssim /= static_cast<double>(eval_views.size());
    if (gt_planes && plane_n > 0) e.depth_plane_rmse_m = std::sqrt(plane_sq / static_cast<double>(plane_n));
    return e;
  };

  double last_loss = std::numeric_limits<double>::quiet_NaN(), last_psnr = last_loss;
  std::map<std::string, double> kernel_ms;  // GPU time per kernel over the run (timestamps)
  const auto t0 = std::chrono::steady_clock::now();
  for (uint32_t it = start; it < o.iterations; ++it) {
    const uint32_t step = it + 1;
    const uint32_t v = sampler.next();
    kernels::SplatCamera cam = data.views[v].camera;
    cam.sh_degree = std::min(o.sh_degree, it / o.sh_degree_every);
    rasterizer.forward(model->gaussians(), cam);  // the iteration's one readback: the intersection count
    for (const auto& k : rasterizer.profile()) kernel_ms[k.name] += k.ms;
    const auto out = rasterizer.device_outputs();
    const auto up = rasterizer.upstream_buffers();

    engine::Sequence s(ctx);
    photometric.record(s, *out.image, views[v].target->buffer(), W, H, static_cast<float>(1.0 - o.lambda_geo),
                       *up.image, losses.buffer(), kSlotPhotometric);
    if (geometric)
      geometric_loss.record(s, *out.depth, views[v].points->buffer(), views[v].normals->buffer(), W, H,
                            static_cast<float>(cam.fx), static_cast<float>(cam.fy), static_cast<float>(cam.cx),
                            static_cast<float>(cam.cy), views[v].valid, static_cast<float>(o.lambda_geo),
                            static_cast<float>(o.geo_robust_scale_m), *up.depth,
                            losses.buffer(), kSlotGeometric);
    else
      s.fill(*up.depth, 0u, uint64_t{W} * H * sizeof(float));
    s.fill(*up.alpha, 0u, uint64_t{W} * H * sizeof(float));
    const auto grads = rasterizer.record_backward(s);
    if (mcmc) mcmc_strategy->record_regularization(s, *model, grads, mopt);
    else if (step < densify_until) model->record_accumulate_stats(s, grads, *out.rects, cam);
    kernels::LearningRates lr = adam.rates(it, o.iterations, extent);
    for (float* r : {&lr.means, &lr.log_scales, &lr.quats, &lr.opacity_logits, &lr.sh_dc, &lr.sh_rest}) *r *= o.lr_scale;
    model->record_adam_step(s, grads, lr, step);
    if (mcmc) mcmc_strategy->record_noise(s, *model, mopt, lr.means, step);
    s.submit_and_wait();
    for (const auto& k : s.profile()) kernel_ms[k.name] += k.ms;

    if (step > o.densify_from && step < densify_until && step % o.densify_every == 0) {
      // The method's geometric outlier removal: Gaussians far from their LiDAR plane, beyond a robust
      // bound of all distances, are pruned with the others.
      const engine::Buffer* plane_distance = nullptr;
      kernels::DensifyOptions step_options = dopt;
      if (plane_index) {
        // Only the means come back to the host, and the distance buffer is reused while it is large enough.
        const DeviceArray<float>& means = model->gaussians().means;
        const std::vector<float> d = plane_index->distances(means.download(0, 3 * model->size()));
        if (!plane_distances || plane_distances->size() < d.size())
          plane_distances = std::make_unique<DeviceArray<float>>(ctx, "train: plane distances",
                                                                 std::max<size_t>(d.size() + d.size() / 2, 1));
        plane_distances->upload(d);
        plane_distance = &plane_distances->buffer();
        step_options.max_plane_distance_m = PlaneDistance::robust_bound(d, o.plane_prune_k);
      }
      if (mcmc) {
        kernels::McmcOptions step_mcmc = mopt;
        step_mcmc.max_plane_distance_m = step_options.max_plane_distance_m;
        const kernels::McmcReport m = mcmc_strategy->relocate_and_grow(*model, step_mcmc, step, plane_distance);
        report.plane_pruned += m.dead_plane;
        report.nonfinite_pruned += m.dead_nonfinite;
      } else {
        const kernels::DensifyReport d = model->densify_and_prune(step_options, extent, step, plane_distance);
        report.plane_pruned += d.pruned_plane;
        report.nonfinite_pruned += d.pruned_nonfinite;
      }
    }
    if (!mcmc && step < densify_until && step % o.opacity_reset_every == 0) {
      engine::Sequence r(ctx);
      model->record_reset_opacity(r);
      r.submit_and_wait();
    }
    const bool last = step == o.iterations;
    if (o.eval_every > 0 && (step % o.eval_every == 0) && !last) {
      report.evals.push_back(evaluate(step));
      last_psnr = report.evals.back().psnr_db;
    }
    if (o.checkpoint_every > 0 && step % o.checkpoint_every == 0) {
      Checkpoint c;
      c.iteration = step;
      sampler.save(c);
      c.state = model->download_state();
      write_checkpoint(out_dir / "checkpoints" / ("iter_" + std::to_string(step) + ".ckpt"), c);
    }
    if (progress && (step % o.progress_every == 0 || last || step == start + 1)) {
      const auto l = losses.download();  // host-visible: written by this iteration's submit
      last_loss = (1.0 - o.lambda_geo) * l[kSlotPhotometric] + (geometric ? o.lambda_geo * l[kSlotGeometric] : 0.0);
      const double geo_rms = geometric ? std::sqrt(std::max(0.0, static_cast<double>(l[kSlotGeometric])))
                                       : std::numeric_limits<double>::quiet_NaN();
      const double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      progress({step, o.iterations, last_loss, l[kSlotPhotometric], geo_rms, last_psnr, model->size(),
                (step - start) / std::max(secs, 1e-9)});
    }
  }
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const double done_iterations = std::max(1.0, static_cast<double>(o.iterations - start));
  for (const auto& [name, ms] : kernel_ms) report.kernel_ms_per_iteration.emplace_back(name, ms / done_iterations);
  report.final_eval = evaluate(o.iterations);
  report.evals.push_back(report.final_eval);
  report.iterations = o.iterations;
  report.wall_s = wall;
  report.ms_per_iteration = o.iterations > start ? 1000.0 * wall / (o.iterations - start) : 0.0;
  report.gaussians = model->size();
  report.peak_device_bytes = engine::Buffer::peak_bytes();

  io::write_gaussian_ply(out_dir / "point_cloud.ply", model->download());
  nlohmann::json metrics = {{"iterations", report.iterations},
                            {"wall_s", report.wall_s},
                            {"ms_per_iteration", report.ms_per_iteration},
                            {"gaussians", report.gaussians},
                            {"peak_device_bytes", report.peak_device_bytes},
                            {"heldout_psnr", report.final_eval.psnr_db},
                            {"heldout_ssim", report.final_eval.ssim},
                            {"heldout_views", eval_views.size()},
                            {"training_views", train_views.size()},
                            {"width", W},
                            {"height", H},
                            {"lambda_geo", o.lambda_geo},
                            {"nonfinite_pruned", report.nonfinite_pruned},
                            {"plane_pruned", report.plane_pruned},
                            {"evaluations", nlohmann::json::array()},
                            {"kernel_ms_per_iteration", nlohmann::json::object()}};
  for (const auto& [name, ms] : report.kernel_ms_per_iteration) metrics["kernel_ms_per_iteration"][name] = ms;
  if (report.final_eval.depth_plane_rmse_m >= 0) metrics["heldout_depth_plane_rmse_m"] = report.final_eval.depth_plane_rmse_m;
  for (const auto& e : report.evals) metrics["evaluations"].push_back(eval_json(e));
  io::write_file_atomic(out_dir / "metrics.json", [&](std::ostream& out) { out << metrics.dump(2) << "\n"; });
  return report;
}

}  // namespace litgs::host
