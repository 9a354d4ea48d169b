#include "calib/circle_grid.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <opencv2/calib3d.hpp>
#include <opencv2/features2d.hpp>
#include <opencv2/imgproc.hpp>
#include <stdexcept>

#include "host/frontend/intensity.h"
#include "io/robust_stats.h"

namespace litgs::calib {
namespace {

cv::Mat to_8bit(const io::Image& image) {
  const io::Image eight = thermal_8bit(image);
  cv::Mat out(eight.height, eight.width, CV_8U);
  for (size_t k = 0; k < eight.data.size(); ++k) out.data[k] = static_cast<uint8_t>(eight.data[k]);
  return out;
}

// Blobs from a few pixels wide up to a tenth of the image: thermal frames are small.
cv::Ptr<cv::FeatureDetector> blob_detector(const cv::Mat& image) {
  cv::SimpleBlobDetector::Params p;
  p.minThreshold = 10;
  p.maxThreshold = 245;
  p.thresholdStep = 5;
  p.minRepeatability = 4;  // a blob must stand 20 levels out of the board: not the background's texture
  p.filterByColor = true;
  p.blobColor = 0;  // dark blobs: cold circles, or hot ones after inversion
  p.filterByArea = true;
  p.minArea = 6;
  p.maxArea = static_cast<float>(image.total()) / 10;
  // A circle seen up to about 60 degrees off its normal stays a convex ellipse with axes at least half
  // apart; the background's blotches are not.
  p.filterByCircularity = true;
  p.minCircularity = 0.6f;
  p.filterByConvexity = true;
  p.minConvexity = 0.85f;
  p.filterByInertia = true;
  p.minInertiaRatio = 0.4f;
  return cv::SimpleBlobDetector::create(p);
}

// Each centre moved to its circle's intensity-weighted centroid in `dark` (circles dark on a brighter
// board), in a window of 0.45 times the distance to the nearest other centre, until it settles. The blob
// detector's centre is the mean of thresholded shapes' centres, which was biased by up to a pixel on
// rendered hot circles; the centroid of the frame's own values is not. Weights: 0 up to two noise sigmas
// below the board's level (the median of the window's outer ring; sigma from its spread), rising to 1 at
// half the way to the circle's level (the window's 5th percentile). Without the dead band every board
// pixel's noise weighs in and pulls the centroid to the window's centre, the detector's estimate.
void refine_centres(const cv::Mat& dark, std::vector<Eigen::Vector2d>& centres) {
  const std::vector<Eigen::Vector2d> start = centres;
  for (size_t k = 0; k < centres.size(); ++k) {
    double nearest = std::numeric_limits<double>::infinity();
    for (size_t m = 0; m < start.size(); ++m)
      if (m != k) nearest = std::min(nearest, (start[m] - start[k]).norm());
    const double radius = 0.45 * nearest;
    if (!(radius >= 2)) continue;
    Eigen::Vector2d c = start[k];
    for (int pass = 0; pass < 6; ++pass) {
      const int x0 = static_cast<int>(std::floor(c.x() - radius)),
                x1 = static_cast<int>(std::ceil(c.x() + radius));
      const int y0 = static_cast<int>(std::floor(c.y() - radius)),
                y1 = static_cast<int>(std::ceil(c.y() + radius));
      if (x0 < 0 || y0 < 0 || x1 >= dark.cols || y1 >= dark.rows) break;
      std::vector<double> ring, disc;
      for (int y = y0; y <= y1; ++y)
        for (int x = x0; x <= x1; ++x) {
          const double d = std::hypot(x - c.x(), y - c.y());
          if (d > radius) continue;
          disc.push_back(dark.at<uint8_t>(y, x));
          if (d > 0.8 * radius) ring.push_back(dark.at<uint8_t>(y, x));
        }
      if (ring.size() < 8) break;
      const double level = io::quantile(ring, 0.5);
      std::vector<double> spread;
      for (double v : ring) spread.push_back(std::abs(v - level));
      const double sigma = 1.4826 * io::quantile(spread, 0.5);
      const double floor = 2 * sigma, full = 0.5 * (level - io::quantile(disc, 0.05));
      // Too noisy to weigh: the detector's centre stays (a narrower band did worse at 32 times synth's
      // noise: focal error 0.29-0.43 % against 0.14-0.29 %).
      if (!(full > floor + 1)) break;
      double w = 0, sx = 0, sy = 0;
      for (int y = y0; y <= y1; ++y)
        for (int x = x0; x <= x1; ++x) {
          if (std::hypot(x - c.x(), y - c.y()) > radius) continue;
          const double weight =
              std::clamp((level - dark.at<uint8_t>(y, x) - floor) / (full - floor), 0.0, 1.0);
          w += weight;
          sx += weight * x;
          sy += weight * y;
        }
      if (!(w > 0)) break;
      const Eigen::Vector2d next(sx / w, sy / w);
      if ((next - start[k]).norm() > 0.5 * radius) break;  // wandered off: keep the last
      const double moved = (next - c).norm();
      c = next;
      if (moved < 1e-3) break;
    }
    centres[k] = c;
  }
}

}  // namespace

io::Image thermal_8bit(const io::Image& image) {
  if (image.channels != 1) throw std::invalid_argument("a one-channel (gray) thermal image is needed");
  io::Image out{image.width, image.height, 1, 8, {}};
  out.data.resize(image.data.size());
  if (image.bit_depth == 8) {
    out.data = image.data;
    return out;
  }
  // The front end's stretch, so that a board is seen as the matcher sees the frames.
  host::frontend::Histogram histogram = host::frontend::empty_histogram();
  host::frontend::add_to_histogram(histogram, image.data);
  const host::frontend::Stretch stretch = host::frontend::percentile_stretch(histogram, 0.5, 99.5);
  for (size_t k = 0; k < image.data.size(); ++k)
    out.data[k] = static_cast<uint16_t>(stretch.unit(image.data[k]) * 255.0 + 0.5);
  return out;
}

std::vector<Eigen::Vector3d> CircleGrid::board_points() const {
  std::vector<Eigen::Vector3d> out;
  for (int i = 0; i < rows; ++i)
    for (int j = 0; j < cols; ++j) out.emplace_back((2 * j + i % 2) * spacing_m, i * spacing_m, 0.0);
  return out;
}

void CircleGrid::check() const {
  if (cols < 2 || rows < 3)
    throw std::invalid_argument("--grid: at least 2 columns and 3 rows, got " + std::to_string(cols) + "x" +
                                std::to_string(rows));
  if (!(spacing_m > 0)) throw std::invalid_argument("--spacing must be > 0 (metres)");
}

CircleGrid parse_circle_grid(const std::string& text, double spacing_m) {
  CircleGrid g;
  const size_t x = text.find('x');
  try {
    size_t used = 0;
    if (x == std::string::npos) throw std::invalid_argument("no x");
    g.cols = std::stoi(text.substr(0, x), &used);
    if (used != x) throw std::invalid_argument("cols");
    g.rows = std::stoi(text.substr(x + 1), &used);
    if (used != text.size() - x - 1) throw std::invalid_argument("rows");
  } catch (const std::exception&) {
    throw std::invalid_argument("--grid: COLSxROWS (e.g. 4x11), not '" + text + "'");
  }
  g.spacing_m = spacing_m;
  g.check();
  return g;
}

Polarity parse_polarity(const std::string& name) {
  if (name == "auto") return Polarity::kAuto;
  if (name == "hot") return Polarity::kHot;
  if (name == "cold") return Polarity::kCold;
  throw std::invalid_argument("--polarity: auto, hot or cold, not '" + name + "'");
}

GridDetection detect_circle_grid(const io::Image& image, const CircleGrid& grid, Polarity polarity,
                                 bool clahe) {
  grid.check();
  GridDetection out;
  const cv::Mat plain = to_8bit(image);
  // CLAHE helps the detection only: its local contrast moves each circle's intensity-weighted centroid, so
  // the centres are refined on the plain stretch (a new buffer: `plain` stays as it is).
  cv::Mat gray = plain;
  if (clahe) {
    gray = cv::Mat();
    cv::createCLAHE(2.0, cv::Size(8, 8))->apply(plain, gray);
  }
  // The blobs are searched for on a smoothed copy (sigma 2 px): a noisy sensor's speckle otherwise makes
  // blobs of its own and breaks the grid's pattern (at 16 times the default noise, no grid was found in 10
  // views; with the smoothing, 10 of 10 up to 32 times). The centres are refined on the plain stretch.
  cv::Mat smooth;
  cv::GaussianBlur(gray, smooth, cv::Size(0, 0), 2.0);
  gray = smooth;
  std::vector<std::string> tried;
  for (const Polarity p : {Polarity::kHot, Polarity::kCold}) {
    if (polarity != Polarity::kAuto && polarity != p) continue;
    const cv::Mat view = p == Polarity::kHot ? cv::Mat(255 - gray) : gray;
    const cv::Ptr<cv::FeatureDetector> detector = blob_detector(view);
    std::vector<cv::Point2f> centres;
    if (cv::findCirclesGrid(view, cv::Size(grid.cols, grid.rows), centres,
                            cv::CALIB_CB_ASYMMETRIC_GRID | cv::CALIB_CB_CLUSTERING, detector)) {
      out.found = true;
      out.polarity = p == Polarity::kHot ? "hot" : "cold";
      for (const auto& c : centres) out.centres.emplace_back(c.x, c.y);
      refine_centres(p == Polarity::kHot ? cv::Mat(255 - plain) : plain, out.centres);
      return out;
    }
    std::vector<cv::KeyPoint> blobs;
    detector->detect(view, blobs);
    tried.push_back(std::to_string(blobs.size()) + (p == Polarity::kHot ? " hot" : " cold") + " blobs");
  }
  out.why_not = "no " + std::to_string(grid.cols) + "x" + std::to_string(grid.rows) + " grid found (";
  for (size_t k = 0; k < tried.size(); ++k) out.why_not += (k ? ", " : "") + tried[k];
  out.why_not += "; the grid needs " + std::to_string(grid.cols * grid.rows) + ")";
  return out;
}

}  // namespace litgs::calib
