// `litgs-engine bench gather`: reading four-float records at scattered indices from a storage buffer (four
// float loads, one vec4 load) against a uniform texel buffer (one fetch), in one run on one device. The
// rasterize kernels' per-entry reads are such gathers; on CPU drivers the way they are read sets their cost.
#include <CLI/CLI.hpp>
#include <iomanip>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <string>
#include <vector>

#include "engine/buffer.h"
#include "engine/context.h"
#include "engine/sequence.h"
#include "kernels/bench/gather_bench.h"
#include "tools/bench_stats.h"
#include "tools/commands.h"
#include "tools/device_json.h"

namespace litgs::tools {
namespace {

struct BenchGatherOptions {
  uint32_t records = 100000;     // records in the array (the rasterizer's: one per Gaussian)
  uint32_t invocations = 65536;  // a multiple of GATHER_BENCH_GROUP_SIZE
  uint32_t rounds = 256;         // records each invocation reads (lavapipe ends loops at 65535 iterations)
  uint32_t runs = 7;             // timed runs per variant after one warm-up; the median is reported
  bool json = false;
  void check() const {
    if (records == 0) throw std::invalid_argument("--records must be positive");
    if (invocations == 0 || invocations % GATHER_BENCH_GROUP_SIZE != 0)
      throw std::invalid_argument("--invocations must be a positive multiple of " +
                                  std::to_string(GATHER_BENCH_GROUP_SIZE) + ", got " +
                                  std::to_string(invocations));
    if (rounds == 0 || rounds > 60000)
      throw std::invalid_argument("--rounds must be in 1..60000, got " + std::to_string(rounds));
    if (runs < 3) throw std::invalid_argument("--runs must be at least 3, got " + std::to_string(runs));
  }
};

struct VariantResult {
  kernels::GatherRead read;
  double ms = 0.0;  // median GPU time of the dispatch
};

void run_bench_gather(const BenchGatherOptions& o) {
  o.check();
  engine::Context context;
  // Small integers: every sum is exact in float, so each variant must return the reference's bits.
  std::vector<float> records(size_t{o.records} * 4);
  for (size_t k = 0; k < records.size(); ++k) records[k] = static_cast<float>(k % 61);
  engine::DeviceArray<float> d_records(context, "bench: gather records", records.size());
  d_records.upload(records);
  engine::DeviceArray<float> d_sums(context, "bench: gather sums", size_t{o.invocations} * 4);
  const kernels::GatherBenchParams params{o.records, o.rounds};
  const std::vector<double> reference = kernels::gather_bench_reference(records, o.invocations, params);

  std::vector<VariantResult> results;
  for (auto read : {kernels::GatherRead::kStorageFloats, kernels::GatherRead::kStorageVec4,
                    kernels::GatherRead::kTexelVec4}) {
    kernels::GatherBench bench(context, read);
    engine::Sequence s(context);
    bench.record(s, d_records, d_sums, params);
    std::vector<double> times;
    for (uint32_t r = 0; r <= o.runs; ++r) {
      s.submit_and_wait();
      if (r > 0) times.push_back(s.device_ms());
    }
    const std::vector<float> sums = d_sums.download();
    for (size_t k = 0; k < sums.size(); ++k)
      if (static_cast<double>(sums[k]) != reference[k])
        throw std::runtime_error(std::string("bench gather: ") + kernels::gather_read_name(read) +
                                 " summed " + std::to_string(sums[k]) + " at value " + std::to_string(k) +
                                 ", expected " + std::to_string(reference[k]));
    results.push_back({read, median(times)});
  }

  const double reads = static_cast<double>(o.invocations) * o.rounds;
  const double baseline_ms = results.front().ms;
  if (o.json) {
    nlohmann::json variants = nlohmann::json::array();
    for (const auto& r : results)
      variants.push_back({{"read", kernels::gather_read_name(r.read)},
                          {"ms", r.ms},
                          {"ns_per_record", r.ms * 1e6 / reads},
                          {"speedup_over_float_loads", r.ms > 0 ? baseline_ms / r.ms : 0.0}});
    nlohmann::json j = {{"records", o.records},
                        {"invocations", o.invocations},
                        {"rounds", o.rounds},
                        {"runs", o.runs},
                        {"variants", variants},
                        {"verified", true},
                        {"device", device_json(context.info())}};
    std::cout << j.dump(2) << "\n";
    return;
  }
  std::cout << std::fixed << std::setprecision(2) << "bench gather: " << o.invocations << " invocations x "
            << o.rounds << " scattered reads of four-float records (" << o.records << " records), median of "
            << o.runs << " runs after a warm-up, on " << context.info().name << "\n";
  for (const auto& r : results)
    std::cout << "  " << std::left << std::setw(38) << kernels::gather_read_name(r.read) << std::right
              << std::setw(9) << r.ms << " ms  " << std::setw(6) << r.ms * 1e6 / reads << " ns per record  "
              << std::setw(5) << (r.ms > 0 ? baseline_ms / r.ms : 0.0) << "x the float loads\n";
  std::cout << "  every variant's sums equal the double reference\n";
}

}  // namespace

void add_bench_gather_command(CLI::App& bench) {
  auto o = std::make_shared<BenchGatherOptions>();
  CLI::App* gather = bench.add_subcommand(
      "gather",
      "Scattered reads of four-float records: storage-buffer loads vs uniform-texel-buffer fetches");
  gather->add_option("--records", o->records, "Records in the array")->capture_default_str();
  gather->add_option("--invocations", o->invocations, "Invocations (a multiple of 64)")
      ->capture_default_str();
  gather->add_option("--rounds", o->rounds, "Records each invocation reads")->capture_default_str();
  gather->add_option("--runs", o->runs, "Timed runs per variant (at least 3)")->capture_default_str();
  gather->add_flag("--json", o->json, "Print one JSON object");
  gather->callback([o] { run_bench_gather(*o); });
}

}  // namespace litgs::tools
