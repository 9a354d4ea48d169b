#include "tools/serve/metrics.h"

#include <unistd.h>

#include <fstream>
#include <sstream>

namespace litgs::serve {

void Metrics::Histogram::add(double v) {
  for (size_t i = 0; i < kBuckets.size(); ++i)
    if (v <= kBuckets[i]) {
      ++le[i];
      break;
    }
  ++count;
  sum += v;
}

void Metrics::Histogram::write(std::string& out, const std::string& name, const std::string& labels) const {
  std::ostringstream s;
  uint64_t cumulative = 0;
  const std::string sep = labels.empty() ? "" : labels + ",";
  for (size_t i = 0; i < kBuckets.size(); ++i) {
    cumulative += le[i];
    s << name << "_bucket{" << sep << "le=\"" << kBuckets[i] << "\"} " << cumulative << "\n";
  }
  s << name << "_bucket{" << sep << "le=\"+Inf\"} " << count << "\n";
  s << name << "_sum" << (labels.empty() ? "" : "{" + labels + "}") << " " << sum << "\n";
  s << name << "_count" << (labels.empty() ? "" : "{" + labels + "}") << " " << count << "\n";
  out += s.str();
}

void Metrics::count_request(const std::string& endpoint, int status, double seconds) {
  std::lock_guard lock(mutex_);
  ++requests_[{endpoint, status}];
  if (endpoint == "/render" && status == 200) render_latency_.add(seconds);
}

void Metrics::count_render(double device_seconds) {
  std::lock_guard lock(mutex_);
  device_time_.add(device_seconds);
}

std::string Metrics::text(const std::string& gauges) const {
  std::string out;
  std::lock_guard lock(mutex_);
  out += "# HELP litgs_http_requests_total HTTP requests answered, by endpoint and status.\n";
  out += "# TYPE litgs_http_requests_total counter\n";
  for (const auto& [key, n] : requests_)
    out += "litgs_http_requests_total{endpoint=\"" + key.first + "\",status=\"" + std::to_string(key.second) +
           "\"} " + std::to_string(n) + "\n";
  out += "# HELP litgs_render_latency_seconds Time from a /render request read to its answer ready (200s).\n";
  out += "# TYPE litgs_render_latency_seconds histogram\n";
  render_latency_.write(out, "litgs_render_latency_seconds", "");
  out += "# HELP litgs_render_device_seconds Time on the device thread per render (forward and download).\n";
  out += "# TYPE litgs_render_device_seconds histogram\n";
  device_time_.write(out, "litgs_render_device_seconds", "");
  out += gauges;
  out += "# HELP process_resident_memory_bytes Resident memory of the server process.\n";
  out += "# TYPE process_resident_memory_bytes gauge\n";
  out += "process_resident_memory_bytes " + std::to_string(resident_bytes()) + "\n";
  return out;
}

uint64_t resident_bytes() {
  std::ifstream in("/proc/self/statm");
  uint64_t size = 0, resident = 0;
  if (!(in >> size >> resident)) return 0;
  return resident * static_cast<uint64_t>(sysconf(_SC_PAGESIZE));
}

}  // namespace litgs::serve
