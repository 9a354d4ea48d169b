#include "host/frontend/appearance.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <nlohmann/json.hpp>

#include "io/scene.h"

namespace litgs::host::frontend {
namespace {

double quantile(const std::vector<double>& share, double q) {
  double cumulative = 0;
  for (int b = 0; b < kGradientBins; ++b) {
    cumulative += share[static_cast<size_t>(b)];
    if (cumulative >= q) return b;
  }
  return kGradientBins - 1;
}

}  // namespace

GradientHistogram gradient_histogram(const std::vector<Gray8>& frames) {
  GradientHistogram h;
  std::vector<double> counts(kGradientBins, 0.0);
  for (const Gray8& f : frames) {
    if (f.width < 3 || f.height < 3) continue;
    auto at = [&f](int x, int y) {
      return static_cast<double>(f.pixels[static_cast<size_t>(y) * f.width + x]);
    };
    for (int y = 1; y + 1 < f.height; ++y)
      for (int x = 1; x + 1 < f.width; ++x) {
        const double gx = (at(x + 1, y - 1) + 2 * at(x + 1, y) + at(x + 1, y + 1)) -
                          (at(x - 1, y - 1) + 2 * at(x - 1, y) + at(x - 1, y + 1));
        const double gy = (at(x - 1, y + 1) + 2 * at(x, y + 1) + at(x + 1, y + 1)) -
                          (at(x - 1, y - 1) + 2 * at(x, y - 1) + at(x + 1, y - 1));
        const double g = std::hypot(gx, gy) / 8;
        counts[static_cast<size_t>(std::min<double>(kGradientBins - 1, std::floor(g)))] += 1;
        ++h.pixels;
      }
  }
  if (h.pixels == 0) return h;
  for (int b = 0; b < kGradientBins; ++b)
    h.share[static_cast<size_t>(b)] = counts[static_cast<size_t>(b)] / static_cast<double>(h.pixels);
  h.median = quantile(h.share, 0.5);
  h.p90 = quantile(h.share, 0.9);
  return h;
}

double histogram_distance(const GradientHistogram& a, const GradientHistogram& b) {
  double ca = 0, cb = 0, distance = 0;
  for (int i = 0; i < kGradientBins; ++i) {
    ca += a.share[static_cast<size_t>(i)];
    cb += b.share[static_cast<size_t>(i)];
    distance += std::abs(ca - cb);  // bins are one grey level wide
  }
  return distance;
}

SceneAppearance measure_appearance(const std::filesystem::path& dir, const FrontendOptions& options) {
  SceneAppearance out;
  const io::Scene scene = io::read_scene(dir, {.check_images = true, .load_map = false});
  PreprocessOptions plain = options.preprocess;
  plain.clahe = false;  // the frames as the camera gives them, stretched: CLAHE would equalize both sets
  std::vector<Gray8> frames;
  for (auto& f : preprocess_frames(dir, scene, plain))
    if (!f.frozen) frames.push_back(std::move(f.image));
  out.gradients = gradient_histogram(frames);
  out.width = scene.config.camera.width;
  out.height = scene.config.camera.height;
  // The frames' matchability, not the map's: a scene without a map (DUNR's) would otherwise be compared
  // against one whose repeated texture the map filters out.
  FrontendOptions frames_only = options;
  frames_only.lidar_check.enabled = false;
  out.frontend = run_frontend(dir, frames_only).summary;
  return out;
}

namespace {

struct Measure {
  const char* name;
  double reference, scene;
};

std::vector<Measure> measures(const SceneAppearance& r, const SceneAppearance& s) {
  auto lost = [](const FrontendSummary& m) {
    return m.track_matches ? static_cast<double>(m.track_conflicts) / static_cast<double>(m.track_matches)
                           : 0.0;
  };
  return {{"gradient median (grey levels/px)", r.gradients.median, s.gradients.median},
          {"gradient 90th percentile", r.gradients.p90, s.gradients.p90},
          {"keypoints per image", r.frontend.keypoints_per_image, s.frontend.keypoints_per_image},
          {"inlier ratio", r.frontend.inlier_ratio, s.frontend.inlier_ratio},
          {"verified matches lost to conflicts", lost(r.frontend), lost(s.frontend)},
          {"mean track length", r.frontend.mean_track_length, s.frontend.mean_track_length}};
}

}  // namespace

std::string compare_appearance_text(const SceneAppearance& r, const SceneAppearance& s) {
  std::string out;
  char line[256];
  std::snprintf(line, sizeof line, "%-36s %12s %12s %9s\n", "", "reference", "scene", "ratio");
  out += line;
  for (const Measure& m : measures(r, s)) {
    std::snprintf(line, sizeof line, "%-36s %12.3f %12.3f %9.2f\n", m.name, m.reference, m.scene,
                  m.reference != 0 ? m.scene / m.reference : 0.0);
    out += line;
  }
  std::snprintf(line, sizeof line, "%-36s %12.3f\n", "gradient histogram distance (EMD)",
                histogram_distance(r.gradients, s.gradients));
  out += line;
  if (r.width != s.width || r.height != s.height) {
    std::snprintf(line, sizeof line,
                  "note: the frames differ in size (%dx%d against %dx%d): compare at one size\n", r.width,
                  r.height, s.width, s.height);
    out += line;
  }
  return out;
}

std::string compare_appearance_json(const SceneAppearance& r, const SceneAppearance& s) {
  nlohmann::json j = {{"histogram_distance", histogram_distance(r.gradients, s.gradients)},
                      {"reference_size", {r.width, r.height}},
                      {"scene_size", {s.width, s.height}},
                      {"reference_histogram", r.gradients.share},
                      {"scene_histogram", s.gradients.share}};
  for (const Measure& m : measures(r, s))
    j["measures"][m.name] = {{"reference", m.reference}, {"scene", m.scene}};
  return j.dump(1);
}

}  // namespace litgs::host::frontend
