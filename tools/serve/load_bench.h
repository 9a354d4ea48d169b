// `litgs-engine bench serve`: a loopback load test of the render service. Starts `litgs-engine serve` as a
// child process on an ephemeral 127.0.0.1 port, then N client threads send a fixed number of POST /render
// requests (views orbiting the model) per image size and round, bounded in time. Each request opens its own
// connection (no keep-alive): a reused connection that the server closes as idle can fail a request in the
// client, which would count as an error that is not the server's.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace litgs::serve {

struct LoadBenchOptions {
  std::string binary;  // litgs-engine
  std::string model;
  std::vector<std::pair<uint32_t, uint32_t>> sizes = {{320, 256}, {640, 512}};
  int clients = 64;
  int requests = 192;              // per size and round
  double request_timeout_s = 120;  // the server's --request-timeout: 64 queued renders take long on a CPU
  int rounds = 2;                  // per size: memory that still grows in the second round would be a leak
  double max_seconds = 300;        // per size: clients stop sending after this
  size_t max_queue = 64;           // the server's --max-queue
};

struct LoadBenchResult {
  uint32_t width = 0, height = 0;
  int round = 1;
  int sent = 0, ok = 0, rejected_503 = 0, errors = 0;  // errors: anything but 200 and 503
  double seconds = 0, throughput = 0, p50_ms = 0, p99_ms = 0, mean_device_ms = 0;
  uint64_t rss_before = 0, rss_after = 0;  // server resident memory before and after this size's load
  std::string first_error;
};

struct LoadBenchReport {
  uint64_t rss_started = 0;  // after the model loaded, before any render
  std::vector<LoadBenchResult> results;
  std::string device;
};

LoadBenchReport run_load_bench(const LoadBenchOptions& options);

}  // namespace litgs::serve
