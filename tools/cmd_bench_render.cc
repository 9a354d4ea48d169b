// `litgs-engine bench render`: forward and forward+backward of the rasterizer on a seeded random scene.
#include <CLI/CLI.hpp>
#include <iomanip>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "engine/context.h"
#include "kernels/splat/rasterizer.h"
#include "tools/bench_scene.h"
#include "tools/bench_stats.h"
#include "tools/commands.h"
#include "tools/device_json.h"
#include "tools/fma_peak.h"
#include "tools/kernel_profile.h"
#include "tools/rasterizer_flops.h"

namespace litgs::tools {
namespace {

struct BenchRenderOptions {
  uint32_t gaussians = 100000;
  uint32_t width = 640, height = 512;
  uint32_t sh_degree = 3;
  uint32_t channels = 1;
  bool backward = false;
  bool deterministic = false;
  uint32_t pixels_per_invocation = 0;  // 0: the device's default (RasterizerOptions)
  uint32_t runs = 5;                   // timed runs after one warm-up
  uint32_t seed = 1;
  bool json = false;
  void check() const {
    if (sh_degree > 3) throw std::invalid_argument("--sh-degree must be 0..3");
    if (channels < 1 || channels > 4) throw std::invalid_argument("--channels must be 1..4");
    if (width == 0 || height == 0) throw std::invalid_argument("--width and --height must be positive");
    if (runs < 1) throw std::invalid_argument("--runs must be at least 1");
    if (pixels_per_invocation != 0 && pixels_per_invocation != 1 && pixels_per_invocation != 8)
      throw std::invalid_argument("--pixels-per-invocation must be 0 (the device's default), 1 or 8");
  }
};

// GPU milliseconds of the profile's kernels whose name starts with `prefix`.
double kernel_ms(const std::vector<engine::KernelTime>& profile, const std::string& prefix) {
  double ms = 0.0;
  for (const auto& k : profile)
    if (k.name.rfind(prefix, 0) == 0) ms += k.ms;
  return ms;
}

// Useful work per second (rasterizer_flops.h) in GFLOP/s and as a fraction of the measured peak.
struct Efficiency {
  double gflops = 0.0, of_peak = 0.0;
};
Efficiency efficiency(double flops, double ms, double peak_gflops) {
  Efficiency e;
  if (ms > 0.0) e.gflops = flops / (ms * 1e6);
  if (peak_gflops > 0.0) e.of_peak = e.gflops / peak_gflops;
  return e;
}

void run_bench_render(const BenchRenderOptions& o) {
  o.check();
  engine::Context context;
  const kernels::GaussianModel model =
      bench_scene(o.gaussians, o.channels, o.sh_degree, o.width, o.height, o.seed);
  const kernels::SplatCamera camera = bench_camera(o.width, o.height, o.sh_degree);
  kernels::DeviceGaussians gaussians(context, model);
  kernels::RasterizerOptions options;
  options.deterministic = o.deterministic;
  options.pixels_per_invocation = o.pixels_per_invocation;
  kernels::Rasterizer rasterizer(context, o.channels, options);

  kernels::RenderGradInput grad;
  std::mt19937 rng(o.seed + 1);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  grad.image.resize(size_t{o.channels} * o.width * o.height);
  for (auto& g : grad.image) g = u(rng);
  grad.depth.assign(size_t{o.width} * o.height, 0.0f);
  grad.alpha.assign(size_t{o.width} * o.height, 0.0f);

  std::vector<double> forward_ms, total_ms;
  for (uint32_t r = 0; r <= o.runs; ++r) {
    const double f = time_ms([&] { rasterizer.forward(gaussians, camera); });
    const double b = o.backward ? time_ms([&] { rasterizer.backward(grad); }) : 0.0;
    if (r == 0) continue;  // warm-up: buffers grow, pipelines warm
    forward_ms.push_back(f);
    total_ms.push_back(f + b);
  }
  const auto& profile = rasterizer.profile();
  const kernels::RasterizerCounters counters = rasterizer.read_counters();
  const double per_gaussian =
      o.gaussians ? static_cast<double>(rasterizer.intersections()) / o.gaussians : 0.0;
  // Useful FLOP/s against the FMA peak measured in this run (same driver, same threads).
  const FmaPeak peak = measure_fma_peak(context);
  const double pairs = counters.contributions;
  const double fwd_flops = pairs * forward_flops_per_pair(o.channels);
  const double bwd_flops = pairs * backward_flops_per_pair(o.channels);
  const Efficiency fwd_kernel =
      efficiency(fwd_flops, kernel_ms(profile, "splat/rasterize_forward"), peak.gflops);
  const Efficiency bwd_kernel =
      efficiency(bwd_flops, kernel_ms(profile, "splat/rasterize_backward"), peak.gflops);
  // The last run's GPU kernel time against the median wall time: what is left is host work (recording,
  // submits, waits, the intersection-count readback). On a fast GPU that is most of it.
  const double all_kernels_ms = kernel_ms(profile, "");
  const double measured_ms = o.backward ? median(total_ms) : median(forward_ms);
  const Efficiency fwd_all = efficiency(fwd_flops, median(forward_ms), peak.gflops);
  const Efficiency both_all =
      efficiency(fwd_flops + bwd_flops, o.backward ? median(total_ms) : 0.0, peak.gflops);
  if (o.json) {
    nlohmann::json j = {{"gaussians", o.gaussians},
                        {"width", o.width},
                        {"height", o.height},
                        {"sh_degree", o.sh_degree},
                        {"channels", o.channels},
                        {"runs", o.runs},
                        {"pixels_per_invocation", rasterizer.pixels_per_invocation()},
                        {"forward_ms", median(forward_ms)},
                        {"gpu_kernels_ms", all_kernels_ms},
                        {"intersections", rasterizer.intersections()},
                        {"kernels", kernel_profile_json(profile)},
                        {"device", device_json(context.info())},
                        {"intersections_per_gaussian", per_gaussian},
                        {"longest_tile_list", counters.longest_tile_list},
                        {"forward_passes", counters.forward_passes},
                        {"backward_passes", counters.backward_passes},
                        {"walks_cut_short", counters.walks_cut_short},
                        {"blended_pairs", counters.contributions},
                        {"fma_peak_gflops", peak.gflops},
                        {"forward_useful_gflops", fwd_all.gflops},
                        {"forward_fraction_of_peak", fwd_all.of_peak},
                        {"rasterize_forward_useful_gflops", fwd_kernel.gflops},
                        {"rasterize_forward_fraction_of_peak", fwd_kernel.of_peak}};
    if (o.backward) {
      j["forward_backward_ms"] = median(total_ms);
      j["forward_backward_useful_gflops"] = both_all.gflops;
      j["forward_backward_fraction_of_peak"] = both_all.of_peak;
      j["rasterize_backward_useful_gflops"] = bwd_kernel.gflops;
      j["rasterize_backward_fraction_of_peak"] = bwd_kernel.of_peak;
    }
    std::cout << j.dump(2) << "\n";
    return;
  }
  std::cout << std::fixed << std::setprecision(2) << "bench render: " << o.gaussians << " Gaussians, "
            << o.width << "x" << o.height << ", " << o.channels << " channel(s), SH degree " << o.sh_degree
            << ", median of " << o.runs << " runs after a warm-up, on " << context.info().name << "\n"
            << "  intersections        " << rasterizer.intersections() << " (" << per_gaussian
            << " per Gaussian)\n"
            << "  pixels / invocation  " << rasterizer.pixels_per_invocation() << "\n"
            << "  longest tile list    " << counters.longest_tile_list
            << " entries: " << counters.forward_passes << " forward pass(es) of "
            << rasterizer.forward_entries_per_pass() << ", " << counters.backward_passes
            << " backward pass(es) of " << rasterizer.backward_entries_per_pass() << "\n"
            << "  walks cut short      " << counters.walks_cut_short
            << " (a driver's loop limit; must be 0)\n"
            << "  forward              " << median(forward_ms) << " ms\n";
  if (o.backward)
    std::cout << "  forward + backward   " << median(total_ms) << " ms"
              << (o.deterministic                   ? " (deterministic)"
                  : rasterizer.uses_float_atomics() ? " (float atomics)"
                                                    : " (CAS atomics)")
              << "\n";
  std::cout << "  GPU kernels          " << all_kernels_ms << " ms of the " << measured_ms
            << " ms above (last run's timestamps; the rest is host work)\n";
  std::cout << "  FMA peak             " << peak.gflops
            << " GFLOP/s (kernels/bench/fma_peak.comp, best of 3)\n"
            << "  blended pairs        " << counters.contributions
            << " (pixel, Gaussian); useful FLOPs per pair " << forward_flops_per_pair(o.channels)
            << " forward, " << backward_flops_per_pair(o.channels) << " backward (tools/rasterizer_flops.h)\n"
            << std::setprecision(1) << "  useful GFLOP/s       forward " << fwd_all.gflops << " ("
            << 100.0 * fwd_all.of_peak << "% of peak), rasterize_forward alone " << fwd_kernel.gflops << " ("
            << 100.0 * fwd_kernel.of_peak << "%)\n";
  if (o.backward)
    std::cout << "                       forward + backward " << both_all.gflops << " ("
              << 100.0 * both_all.of_peak << "% of peak), rasterize_backward alone " << bwd_kernel.gflops
              << " (" << 100.0 * bwd_kernel.of_peak << "%)\n";
  std::cout << std::setprecision(2);
  print_kernel_profile(std::cout, profile);
}

}  // namespace

void add_bench_render_command(CLI::App& bench) {
  auto o = std::make_shared<BenchRenderOptions>();
  CLI::App* cmd =
      bench.add_subcommand("render", "Rasterizer forward (and backward) on a seeded random scene");
  cmd->add_option("--gaussians", o->gaussians, "Number of Gaussians")->capture_default_str();
  cmd->add_option("--width", o->width, "Image width")->capture_default_str();
  cmd->add_option("--height", o->height, "Image height")->capture_default_str();
  cmd->add_option("--sh-degree", o->sh_degree, "SH degree 0..3")->capture_default_str();
  cmd->add_option("--channels", o->channels, "Channels (1 thermal, 3 RGB)")->capture_default_str();
  cmd->add_flag("--backward", o->backward, "Also time forward + backward");
  cmd->add_flag("--deterministic", o->deterministic, "Deterministic backward (no float atomics)");
  cmd->add_option("--pixels-per-invocation", o->pixels_per_invocation,
                  "Rasterize layout: 8 (2x4 blocks) or 1; 0: the device's default (8 on a CPU, 1 on a GPU)")
      ->capture_default_str();
  cmd->add_option("--runs", o->runs, "Timed runs after one warm-up")->capture_default_str();
  cmd->add_option("--seed", o->seed, "Scene seed")->capture_default_str();
  cmd->add_flag("--json", o->json, "Print one JSON object");
  cmd->callback([o] { run_bench_render(*o); });
}

}  // namespace litgs::tools
