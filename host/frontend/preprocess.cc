#include "host/frontend/preprocess.h"

#include <algorithm>
#include <opencv2/imgproc.hpp>
#include <stdexcept>
#include <string>

#include "host/frontend/frozen_frames.h"

namespace litgs::host::frontend {

void PreprocessOptions::check() const {
  if (!(low_percentile >= 0 && low_percentile < high_percentile && high_percentile <= 100))
    throw std::invalid_argument("preprocess: percentiles must satisfy 0 <= low < high <= 100");
  if (!(clahe_clip_limit > 0)) throw std::invalid_argument("preprocess: clahe_clip_limit must be > 0");
  if (clahe_tiles < 1 || clahe_tiles > 64)
    throw std::invalid_argument("preprocess: clahe_tiles must be in 1..64, got " +
                                std::to_string(clahe_tiles));
  if (!(frozen_threshold >= 0)) throw std::invalid_argument("preprocess: frozen_threshold must be >= 0");
}

Gray8 resize_gray8(const Gray8& image, int width, int height) {
  if (width < 1 || height < 1 || image.pixels.size() != size_t(image.width) * size_t(image.height))
    throw std::invalid_argument("resize_gray8: an empty image or size");
  Gray8 out{width, height, std::vector<uint8_t>(size_t(width) * size_t(height))};
  const cv::Mat in(image.height, image.width, CV_8UC1, const_cast<uint8_t*>(image.pixels.data()));
  cv::Mat resized(height, width, CV_8UC1, out.pixels.data());
  cv::resize(in, resized, cv::Size(width, height), 0, 0, cv::INTER_LINEAR);
  return out;
}

Gray8 to_gray8(const io::Image& raw, const Stretch& stretch, const PreprocessOptions& o) {
  Gray8 g{raw.width, raw.height, std::vector<uint8_t>(static_cast<size_t>(raw.width) * raw.height)};
  const size_t channels = static_cast<size_t>(raw.channels);
  for (size_t p = 0; p < g.pixels.size(); ++p)
    g.pixels[p] = static_cast<uint8_t>(stretch.unit(raw.data[p * channels]) * 255.0f + 0.5f);
  if (o.clahe && !g.pixels.empty()) {
    cv::Mat m(g.height, g.width, CV_8UC1, g.pixels.data());
    cv::Ptr<cv::CLAHE> clahe = cv::createCLAHE(o.clahe_clip_limit, cv::Size(o.clahe_tiles, o.clahe_tiles));
    cv::Mat out;
    clahe->apply(m, out);
    out.copyTo(m);
  }
  return g;
}

std::vector<PreprocessedFrame> preprocess_frames(const std::filesystem::path& dir, const io::Scene& scene,
                                                 const PreprocessOptions& o) {
  o.check();
  const bool sixteen = scene.config.camera.bit_depth == 16;
  std::vector<io::Image> raw;
  std::vector<Histogram> histograms;
  for (size_t i = 0; i < scene.frames.size(); ++i) {
    raw.push_back(io::load_frame(dir, scene, i));
    histograms.push_back(empty_histogram());
    add_to_histogram(histograms.back(), raw.back().data, static_cast<size_t>(raw.back().channels));
  }
  std::vector<PreprocessedFrame> out(raw.size());
  if (raw.empty()) return out;
  // The frozen test always uses the sequence's one stretch (as training does), whatever the window.
  const Stretch shared =
      sixteen ? sequence_stretch(histograms, o.low_percentile, o.high_percentile, 0)[0] : Stretch{0, 255};
  const std::vector<Stretch> stretches =
      sixteen ? sequence_stretch(histograms, o.low_percentile, o.high_percentile, o.stretch_window)
              : std::vector<Stretch>(raw.size(), Stretch{0, 255});
  FrozenFrameDetector frozen(o.frozen_threshold);
  for (size_t i = 0; i < raw.size(); ++i) {
    std::vector<float> unit(static_cast<size_t>(raw[i].width) * raw[i].height);
    for (size_t p = 0; p < unit.size(); ++p) unit[p] = shared.unit(raw[i].data[p * raw[i].channels]);
    out[i].stretch = stretches[i];
    out[i].frozen = frozen.is_frozen(unit);
    if (out[i].frozen) continue;
    out[i].image = to_gray8(raw[i], stretches[i], o);
    const auto [lo, hi] = std::minmax_element(out[i].image.pixels.begin(), out[i].image.pixels.end());
    out[i].uniform = lo == out[i].image.pixels.end() || *lo == *hi;
  }
  return out;
}

}  // namespace litgs::host::frontend
