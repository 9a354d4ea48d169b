// `litgs-engine bench serve`: the render service under load on loopback (tools/serve/load_bench.h).
#include <CLI/CLI.hpp>
#include <iomanip>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>

#include "tools/commands.h"
#include "tools/serve/load_bench.h"

namespace litgs::tools {
namespace {

double mib(uint64_t bytes) {
  return static_cast<double>(bytes) / 1048576.0;
}

}  // namespace

void add_bench_serve_command(CLI::App& bench) {
  auto o = std::make_shared<serve::LoadBenchOptions>();
  auto json_out = std::make_shared<bool>(false);
  CLI::App* cmd = bench.add_subcommand(
      "serve", "Loopback load test of `serve`: concurrent clients, throughput, p50/p99 latency, memory");
  cmd->add_option("--model", o->model, "3DGS PLY model to serve")->required()->check(CLI::ExistingFile);
  cmd->add_option("--clients", o->clients, "Concurrent clients")->capture_default_str();
  cmd->add_option("--requests", o->requests, "Requests per image size and round")->capture_default_str();
  cmd->add_option("--rounds", o->rounds, "Rounds per image size (memory after each)")->capture_default_str();
  cmd->add_option("--max-seconds", o->max_seconds, "Time bound per image size")->capture_default_str();
  cmd->add_option("--max-queue", o->max_queue, "The server's --max-queue")->capture_default_str();
  cmd->add_option("--request-timeout", o->request_timeout_s, "The server's --request-timeout (s)")
      ->capture_default_str();
  cmd->add_flag("--json", *json_out, "One JSON object instead of the table");
  cmd->callback([o, json_out] {
    o->binary = "/proc/self/exe";
    const serve::LoadBenchReport report = serve::run_load_bench(*o);
    if (*json_out) {
      nlohmann::json j = {
          {"device", report.device}, {"rss_started", report.rss_started}, {"clients", o->clients}};
      for (const auto& r : report.results)
        j["sizes"].push_back({{"width", r.width},
                              {"height", r.height},
                              {"round", r.round},
                              {"ok", r.ok},
                              {"rejected_503", r.rejected_503},
                              {"errors", r.errors},
                              {"seconds", r.seconds},
                              {"throughput", r.throughput},
                              {"p50_ms", r.p50_ms},
                              {"p99_ms", r.p99_ms},
                              {"mean_device_ms", r.mean_device_ms},
                              {"rss_before", r.rss_before},
                              {"rss_after", r.rss_after}});
      std::cout << j.dump(2) << "\n";
    } else {
      std::cout << "bench serve: " << o->clients << " clients, " << o->requests << " requests per size, on "
                << report.device << "; server RSS after loading " << mib(report.rss_started) << " MiB\n";
      std::cout << "  size     round     ok    503  errors  req/s   p50 ms   p99 ms  device ms  RSS before "
                   "-> after (MiB)\n";
      for (const auto& r : report.results)
        std::cout << "  " << std::setw(3) << r.width << "x" << std::left << std::setw(4) << r.height
                  << std::right << std::setw(6) << r.round << std::setw(7) << r.ok << std::setw(7)
                  << r.rejected_503 << std::setw(8) << r.errors << std::fixed << std::setprecision(1)
                  << std::setw(7) << r.throughput << std::setw(9) << r.p50_ms << std::setw(9) << r.p99_ms
                  << std::setw(11) << r.mean_device_ms << "  " << mib(r.rss_before) << " -> "
                  << mib(r.rss_after) << "\n";
      for (const auto& r : report.results)
        if (!r.first_error.empty())
          std::cout << "  first error at " << r.width << "x" << r.height << ": " << r.first_error << "\n";
    }
    for (const auto& r : report.results)
      if (r.errors > 0) throw std::runtime_error("bench serve: requests failed (see above)");
  });
}

}  // namespace litgs::tools
