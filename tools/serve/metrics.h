// The service's counters in the Prometheus text format (GET /metrics): requests by endpoint and status, a
// latency histogram of /render, the device time per render, the queue depth and the models' sizes (filled
// in by the caller), and the process's resident memory.
#pragma once

#include <array>
#include <cstdint>
#include <map>
#include <mutex>
#include <string>
#include <utility>

namespace litgs::serve {

class Metrics {
 public:
  void count_request(const std::string& endpoint, int status, double seconds);
  void count_render(double device_seconds);
  // `gauges`: extra lines written as they are (queue depth, model sizes).
  std::string text(const std::string& gauges) const;

 private:
  static constexpr std::array<double, 12> kBuckets = {0.005, 0.01, 0.025, 0.05, 0.1,  0.25,
                                                      0.5,   1.0,  2.5,   5.0,  10.0, 30.0};
  struct Histogram {
    std::array<uint64_t, kBuckets.size()> le{};  // cumulative on output, per bucket here
    uint64_t count = 0;
    double sum = 0;
    void add(double v);
    void write(std::string& out, const std::string& name, const std::string& labels) const;
  };
  mutable std::mutex mutex_;
  std::map<std::pair<std::string, int>, uint64_t> requests_;
  Histogram render_latency_, device_time_;
};

// Resident set size of this process in bytes (/proc/self/statm), 0 where unknown.
uint64_t resident_bytes();

}  // namespace litgs::serve
