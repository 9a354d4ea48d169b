#include "tools/serve/load_bench.h"

#include <httplib.h>
#include <signal.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <mutex>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <thread>

#include "tools/serve/server_process.h"

namespace litgs::serve {
namespace {

using nlohmann::json;

// T_cam_world of a camera at `eye` looking at `target`, z up (OpenCV axes: x right, y down, z forward).
json look_at(const std::array<double, 3>& eye, const std::array<double, 3>& target) {
  auto sub = [](auto a, auto b) { return std::array<double, 3>{a[0] - b[0], a[1] - b[1], a[2] - b[2]}; };
  auto cross = [](auto a, auto b) {
    return std::array<double, 3>{a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2],
                                 a[0] * b[1] - a[1] * b[0]};
  };
  auto unit = [](auto a) {
    const double n = std::sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]);
    return std::array<double, 3>{a[0] / n, a[1] / n, a[2] / n};
  };
  const auto z = unit(sub(target, eye));
  const auto x = unit(cross(z, std::array<double, 3>{0, 0, 1}));
  const auto y = cross(z, x);
  const double R[3][3] = {{x[0], x[1], x[2]}, {y[0], y[1], y[2]}, {z[0], z[1], z[2]}};  // rows: camera axes
  const double trace = R[0][0] + R[1][1] + R[2][2];
  double w, qx, qy, qz;  // rotation matrix to quaternion (trace > -1 holds for these views)
  if (trace > -0.99) {
    const double s = std::sqrt(1.0 + trace) * 2;
    w = 0.25 * s, qx = (R[2][1] - R[1][2]) / s, qy = (R[0][2] - R[2][0]) / s, qz = (R[1][0] - R[0][1]) / s;
  } else {
    w = 0, qx = 1, qy = 0, qz = 0;
  }
  const double n = std::sqrt(w * w + qx * qx + qy * qy + qz * qz);
  const double t[3] = {-(R[0][0] * eye[0] + R[0][1] * eye[1] + R[0][2] * eye[2]),
                       -(R[1][0] * eye[0] + R[1][1] * eye[1] + R[1][2] * eye[2]),
                       -(R[2][0] * eye[0] + R[2][1] * eye[1] + R[2][2] * eye[2])};
  return {{"q", {w / n, qx / n, qy / n, qz / n}}, {"t", {t[0], t[1], t[2]}}};
}

double percentile(std::vector<double> v, double p) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  // Nearest rank: the smallest value with at least p% of the values at or below it.
  const double rank = std::ceil(p / 100.0 * static_cast<double>(v.size()));
  return v[std::clamp<size_t>(static_cast<size_t>(rank), 1, v.size()) - 1];
}

LoadBenchResult run_size(const LoadBenchOptions& o, ServerProcess& server, const json& model, uint32_t w,
                         uint32_t h) {
  std::array<double, 3> centre{}, lo{}, hi{};
  for (int a = 0; a < 3; ++a) {
    lo[a] = model["bounds"]["min"][a];
    hi[a] = model["bounds"]["max"][a];
    centre[a] = 0.5 * (lo[a] + hi[a]);
  }
  const double extent = std::max({hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2], 1e-3});
  LoadBenchResult r;
  r.width = w;
  r.height = h;
  const auto request_body = [&](int i) {
    const double angle = 2 * M_PI * (i % 64) / 64.0;
    const std::array<double, 3> eye = {centre[0] + 1.2 * extent * std::cos(angle),
                                       centre[1] + 1.2 * extent * std::sin(angle), centre[2] + 0.4 * extent};
    return json{{"pose", {{"T_cam_world", look_at(eye, centre)}}},
                {"intrinsics", {{"fov_y_deg", 60}}},
                {"width", w},
                {"height", h}}
        .dump();
  };
  // One warm-up request: the first render of a size grows the rasterizer's buffers.
  {
    httplib::Client warm("127.0.0.1", server.port());
    warm.set_read_timeout(120, 0);
    const auto res = warm.Post("/render", request_body(0), "application/json");
    if (!res || res->status != 200) throw std::runtime_error("bench serve: the warm-up render failed");
  }
  r.rss_before = server.resident_bytes();
  std::atomic<int> next{0};
  std::mutex mutex;
  std::vector<double> latencies_ms, device_ms;
  const auto start = std::chrono::steady_clock::now();
  const auto deadline = start + std::chrono::duration<double>(o.max_seconds);
  std::vector<std::thread> clients;
  for (int c = 0; c < o.clients; ++c)
    clients.emplace_back([&] {
      httplib::Client client("127.0.0.1", server.port());
      client.set_read_timeout(static_cast<time_t>(o.request_timeout_s) + 60, 0);
      for (int i = next++; i < o.requests && std::chrono::steady_clock::now() < deadline; i = next++) {
        const std::string body = request_body(i);
        for (;;) {  // a 503 is the server's deliberate refusal: counted, then the same request again
          const auto t0 = std::chrono::steady_clock::now();
          const auto res = client.Post("/render", body, "application/json");
          const double ms =
              std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
          std::unique_lock lock(mutex);
          ++r.sent;
          if (res && res->status == 503) {
            ++r.rejected_503;
            if (std::chrono::steady_clock::now() > deadline) break;
            lock.unlock();
            std::this_thread::sleep_for(std::chrono::milliseconds(50));
            continue;
          }
          if (res && res->status == 200) {
            ++r.ok;
            latencies_ms.push_back(ms);
            device_ms.push_back(std::stod(res->get_header_value("X-Device-Ms")));
          } else {
            ++r.errors;
            if (r.first_error.empty())
              r.first_error =
                  res ? std::to_string(res->status) + " " + res->body : httplib::to_string(res.error());
          }
          break;
        }
      }
    });
  for (std::thread& t : clients) t.join();
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  r.rss_after = server.resident_bytes();
  r.throughput = r.ok / r.seconds;
  r.p50_ms = percentile(latencies_ms, 50);
  r.p99_ms = percentile(latencies_ms, 99);
  double sum = 0;
  for (double d : device_ms) sum += d;
  r.mean_device_ms = device_ms.empty() ? 0 : sum / static_cast<double>(device_ms.size());
  return r;
}

}  // namespace

LoadBenchReport run_load_bench(const LoadBenchOptions& o) {
  if (o.clients < 1 || o.requests < 1 || o.rounds < 1 || !(o.max_seconds > 0))
    throw std::invalid_argument(
        "bench serve: --clients, --requests, --rounds and --max-seconds must be positive");
  ServerProcess server(o.binary, {"--model", o.model, "--max-queue", std::to_string(o.max_queue),
                                  "--request-timeout", std::to_string(o.request_timeout_s)});
  LoadBenchReport report;
  report.rss_started = server.resident_bytes();
  httplib::Client info("127.0.0.1", server.port());
  const auto res = info.Get("/model");
  if (!res || res->status != 200) throw std::runtime_error("bench serve: GET /model failed");
  const json model = json::parse(res->body);
  report.device = model.value("device", "");
  for (const auto& [w, h] : o.sizes)
    for (int round = 1; round <= o.rounds; ++round) {
      report.results.push_back(run_size(o, server, model, w, h));
      report.results.back().round = round;
    }
  const int status = server.stop(SIGTERM);
  if (status != 0) throw std::runtime_error("bench serve: the server exited with " + std::to_string(status));
  return report;
}

}  // namespace litgs::serve
