// `litgs-engine bench loss`: the photometric loss (forward + backward, one sequence) on random images.
#include <CLI/CLI.hpp>
#include <iomanip>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <random>
#include <stdexcept>
#include <vector>

#include "engine/buffer.h"
#include "engine/context.h"
#include "engine/sequence.h"
#include "kernels/loss/photometric_loss.h"
#include "tools/bench_stats.h"
#include "tools/commands.h"
#include "tools/device_json.h"
#include "tools/kernel_profile.h"

namespace litgs::tools {
namespace {

struct BenchLossOptions {
  uint32_t width = 640, height = 512;
  uint32_t channels = 1;
  float lambda_ssim = 0.2f;
  uint32_t runs = 9;  // timed runs after one warm-up
  uint32_t seed = 1;
  bool json = false;
  void check() const {
    if (channels < 1 || channels > 4) throw std::invalid_argument("--channels must be 1..4");
    if (width == 0 || height == 0) throw std::invalid_argument("--width and --height must be positive");
    if (runs < 1) throw std::invalid_argument("--runs must be at least 1");
  }
};

void run_bench_loss(const BenchLossOptions& o) {
  o.check();
  engine::Context context;
  const size_t n = size_t{o.channels} * o.width * o.height;
  std::mt19937 rng(o.seed);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  std::vector<float> x(n), y(n);
  for (size_t i = 0; i < n; ++i) {
    y[i] = u(rng);
    x[i] = 0.8f * y[i] + 0.2f * u(rng);  // correlated, as a render and its target
  }
  engine::DeviceArray<float> image(context, "bench: image", n), target(context, "bench: target", n);
  engine::DeviceArray<float> grad(context, "bench: grad", n), out(context, "bench: loss", 3);
  image.upload(x);
  target.upload(y);
  kernels::PhotometricLossOptions options;
  options.lambda_ssim = o.lambda_ssim;
  kernels::PhotometricLoss loss(context, o.channels, options);
  engine::Sequence seq(context);
  loss.record(seq, image.buffer(), target.buffer(), o.width, o.height, 1.0f, grad.buffer(), out.buffer(), 0);

  std::vector<double> wall_ms, device_ms;
  for (uint32_t r = 0; r <= o.runs; ++r) {
    const double t = time_ms([&] { seq.submit_and_wait(); });
    if (r == 0) continue;  // warm-up
    wall_ms.push_back(t);
    device_ms.push_back(seq.device_ms());
  }
  const auto values = out.download();
  const auto profile = seq.profile();
  if (o.json) {
    nlohmann::json j = {{"width", o.width},
                        {"height", o.height},
                        {"channels", o.channels},
                        {"runs", o.runs},
                        {"forward_backward_ms", median(wall_ms)},
                        {"device_ms", median(device_ms)},
                        {"loss", values[0]},
                        {"mean_ssim", values[1]},
                        {"mean_l1", values[2]},
                        {"kernels", kernel_profile_json(profile)},
                        {"device", device_json(context.info())}};
    std::cout << j.dump(2) << "\n";
    return;
  }
  std::cout << std::fixed << std::setprecision(2) << "bench loss: photometric, " << o.width << "x" << o.height
            << ", " << o.channels << " channel(s), lambda_ssim " << o.lambda_ssim << ", median of " << o.runs
            << " runs after a warm-up, on " << context.info().name << "\n"
            << "  forward + backward   " << median(wall_ms) << " ms (submit to wait), " << median(device_ms)
            << " ms GPU\n"
            << std::setprecision(5) << "  loss " << values[0] << ", mean SSIM " << values[1] << ", mean L1 "
            << values[2] << "\n";
  print_kernel_profile(std::cout, profile);
}

}  // namespace

void add_bench_loss_command(CLI::App& bench) {
  auto o = std::make_shared<BenchLossOptions>();
  CLI::App* cmd = bench.add_subcommand("loss", "Photometric loss forward + backward on random images");
  cmd->add_option("--width", o->width, "Image width")->capture_default_str();
  cmd->add_option("--height", o->height, "Image height")->capture_default_str();
  cmd->add_option("--channels", o->channels, "Channels (1 thermal, 3 RGB)")->capture_default_str();
  cmd->add_option("--lambda-ssim", o->lambda_ssim, "Weight of D-SSIM")->capture_default_str();
  cmd->add_option("--runs", o->runs, "Timed runs after one warm-up")->capture_default_str();
  cmd->add_option("--seed", o->seed, "Image seed")->capture_default_str();
  cmd->add_flag("--json", o->json, "Print one JSON object");
  cmd->callback([o] { run_bench_loss(*o); });
}

}  // namespace litgs::tools
