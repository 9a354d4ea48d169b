// `litgs-engine bench sort`: the device radix sort against std::stable_sort on the same pairs, same process.
#include <CLI/CLI.hpp>
#include <algorithm>
#include <iomanip>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <random>
#include <stdexcept>
#include <utility>
#include <vector>

#include "engine/buffer.h"
#include "engine/context.h"
#include "engine/sequence.h"
#include "kernels/sort/radix_sort.h"
#include "tools/bench_stats.h"
#include "tools/commands.h"
#include "tools/device_json.h"
#include "tools/kernel_profile.h"

namespace litgs::tools {
namespace {

struct BenchSortOptions {
  uint32_t n = 1u << 20;  // pairs to sort
  uint32_t bits = 32;     // low key bits sorted on (random keys use exactly these bits)
  uint32_t runs = 7;      // timed runs after one warm-up; the median is reported
  uint32_t seed = 1;      // key generator seed
  bool json = false;
  void check() const {
    if (bits < 1 || bits > 32)
      throw std::invalid_argument("--bits must be in 1..32, got " + std::to_string(bits));
    if (runs < 5) throw std::invalid_argument("--runs must be at least 5, got " + std::to_string(runs));
  }
};

void run_bench_sort(const BenchSortOptions& o) {
  o.check();
  std::mt19937 rng(o.seed);
  const uint32_t mask = o.bits == 32 ? 0xFFFFFFFFu : (1u << o.bits) - 1u;
  std::vector<uint32_t> keys(o.n), values(o.n);
  for (uint32_t i = 0; i < o.n; ++i) {
    keys[i] = static_cast<uint32_t>(rng()) & mask;
    values[i] = i;
  }

  // CPU baseline: std::stable_sort of the same (key, value) pairs by key.
  std::vector<std::pair<uint32_t, uint32_t>> pairs(o.n);
  std::vector<double> cpu_times;
  for (uint32_t r = 0; r <= o.runs; ++r) {
    for (uint32_t i = 0; i < o.n; ++i) pairs[i] = {keys[i], values[i]};
    const double ms = time_ms([&] {
      std::stable_sort(pairs.begin(), pairs.end(),
                       [](const auto& a, const auto& b) { return a.first < b.first; });
    });
    if (r > 0) cpu_times.push_back(ms);  // run 0 warms caches and the allocator
  }

  engine::Context context;
  kernels::RadixSort sort(context);
  engine::DeviceArray<uint32_t> d_keys(context, "bench keys", o.n);
  engine::DeviceArray<uint32_t> d_values(context, "bench values", o.n);
  engine::Sequence sequence(context);
  sort.record(sequence, d_keys, d_values, o.n, o.bits);

  std::vector<double> device_times, gpu_times;
  for (uint32_t r = 0; r <= o.runs; ++r) {
    d_keys.upload(keys);
    d_values.upload(values);
    const double ms = time_ms([&] { sequence.submit_and_wait(); });
    if (r > 0) {
      device_times.push_back(ms);
      gpu_times.push_back(sequence.device_ms());
    }
  }
  const std::vector<uint32_t> out_keys = d_keys.download();
  const std::vector<uint32_t> out_values = d_values.download();
  bool verified = true;
  for (uint32_t i = 0; i < o.n && verified; ++i)
    verified = out_keys[i] == pairs[i].first && out_values[i] == pairs[i].second;
  if (!verified) throw std::runtime_error("bench sort: the device result differs from std::stable_sort");

  const double device_ms = median(device_times), cpu_ms = median(cpu_times);
  const double ratio = device_ms > 0 ? cpu_ms / device_ms : 0.0;
  const auto layout = sort.layout(o.n);
  const auto profile = sequence.profile();
  if (o.json) {
    nlohmann::json j = {{"n", o.n},
                        {"bits", o.bits},
                        {"runs", o.runs},
                        {"device_ms", device_ms},
                        {"device_timestamps_ms", median(gpu_times)},
                        {"cpu_ms", cpu_ms},
                        {"ratio", ratio},
                        {"device_mkeys_per_s", device_ms > 0 ? o.n / device_ms * 1e-3 : 0.0},
                        {"cpu_mkeys_per_s", cpu_ms > 0 ? o.n / cpu_ms * 1e-3 : 0.0},
                        {"verified", verified},
                        {"block_size", layout.block_size},
                        {"block_count", layout.block_count},
                        {"kernels", kernel_profile_json(profile)},
                        {"device", device_json(context.info())}};
    std::cout << j.dump(2) << "\n";
    return;
  }
  std::cout << std::fixed << std::setprecision(2);
  std::cout << "bench sort: " << o.n << " random (uint32 key, uint32 value) pairs, " << o.bits
            << " key bits, median of " << o.runs << " runs after a warm-up\n"
            << "  device  " << context.info().name << " (subgroup " << context.info().subgroup_size << ", "
            << layout.block_count << " blocks of " << layout.block_size << ")\n"
            << "  device sort       " << std::setw(9) << device_ms << " ms  " << std::setw(8)
            << (device_ms > 0 ? o.n / device_ms * 1e-3 : 0.0) << " Mkeys/s  (GPU timestamps "
            << median(gpu_times) << " ms)\n"
            << "  std::stable_sort  " << std::setw(9) << cpu_ms << " ms  " << std::setw(8)
            << (cpu_ms > 0 ? o.n / cpu_ms * 1e-3 : 0.0) << " Mkeys/s\n"
            << "  ratio (cpu / device) " << ratio << "x; device result equals std::stable_sort\n";
  print_kernel_profile(std::cout, profile);
}

}  // namespace

void add_bench_sort_command(CLI::App& bench) {
  auto o = std::make_shared<BenchSortOptions>();
  CLI::App* sort =
      bench.add_subcommand("sort", "Device radix sort of random key-value pairs vs std::stable_sort");
  sort->add_option("--n", o->n, "Pairs to sort")->capture_default_str();
  sort->add_option("--bits", o->bits, "Low key bits to sort on (1..32)")->capture_default_str();
  sort->add_option("--runs", o->runs, "Timed runs (at least 5) after one warm-up")->capture_default_str();
  sort->add_option("--seed", o->seed, "Random seed of the keys")->capture_default_str();
  sort->add_flag("--json", o->json, "Print one JSON object");
  sort->callback([o] { run_bench_sort(*o); });
}

}  // namespace litgs::tools
