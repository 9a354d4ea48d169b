#include "calib/intrinsics.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <opencv2/calib3d.hpp>
#include <stdexcept>

#include "io/robust_stats.h"

namespace litgs::calib {
namespace {

struct Solve {
  cv::Matx33d K;
  cv::Mat dist;
  std::vector<double> per_view_rms, stddev;
  double rms = 0;
};

Solve solve(const std::vector<std::vector<cv::Point3f>>& object,
            const std::vector<std::vector<cv::Point2f>>& image, cv::Size size, io::CameraModel model) {
  Solve s;
  std::vector<cv::Mat> rvecs, tvecs;
  const cv::TermCriteria stop(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 100, 1e-12);
  if (model == io::CameraModel::kPinhole) {
    cv::Mat K, dist, std_intrinsics, std_extrinsics, errors;
    s.rms = cv::calibrateCamera(object, image, size, K, dist, rvecs, tvecs, std_intrinsics, std_extrinsics,
                                errors, cv::CALIB_FIX_K3, stop);
    s.K = K;
    s.dist = dist.reshape(1, 1).colRange(0, 4).clone();
    for (int k = 0; k < errors.rows; ++k) s.per_view_rms.push_back(errors.at<double>(k));
    for (int k = 0; k < 8; ++k) s.stddev.push_back(std_intrinsics.at<double>(k));
    return s;
  }
  std::vector<std::vector<cv::Point3d>> object_d;
  std::vector<std::vector<cv::Point2d>> image_d;
  for (size_t v = 0; v < object.size(); ++v) {
    object_d.emplace_back(object[v].begin(), object[v].end());
    image_d.emplace_back(image[v].begin(), image[v].end());
  }
  cv::Matx33d K;
  cv::Vec4d dist;
  s.rms = cv::fisheye::calibrate(object_d, image_d, size, K, dist, rvecs, tvecs,
                                 cv::fisheye::CALIB_RECOMPUTE_EXTRINSIC | cv::fisheye::CALIB_FIX_SKEW, stop);
  s.K = K;
  s.dist = cv::Mat(dist).reshape(1, 1).clone();
  for (size_t v = 0; v < object_d.size(); ++v) {
    std::vector<cv::Point2d> projected;
    cv::fisheye::projectPoints(object_d[v], projected, rvecs[v], tvecs[v], K, dist);
    double sum = 0;
    for (size_t k = 0; k < projected.size(); ++k) sum += std::pow(cv::norm(projected[k] - image_d[v][k]), 2);
    s.per_view_rms.push_back(std::sqrt(sum / static_cast<double>(projected.size())));
  }
  return s;
}

}  // namespace

void IntrinsicsOptions::check() const {
  if (min_views < 3) throw std::invalid_argument("calibration: min_views must be >= 3");
  if (!(outlier_k > 0)) throw std::invalid_argument("calibration: outlier_k must be > 0");
}

IntrinsicsResult calibrate_intrinsics(const std::vector<CalibrationView>& views, const CircleGrid& grid,
                                      const IntrinsicsOptions& o) {
  o.check();
  grid.check();
  IntrinsicsResult r;
  // The set's size: the most common among the views that show the grid.
  std::map<std::pair<int, int>, size_t> sizes;
  for (const auto& v : views)
    if (v.detection.found) ++sizes[{v.width, v.height}];
  std::pair<int, int> size{0, 0};
  size_t most = 0;
  for (const auto& [s, n] : sizes)
    if (n > most) most = n, size = s;
  std::vector<size_t> candidates;
  size_t without_grid = 0, other_size = 0;
  for (size_t k = 0; k < views.size(); ++k) {
    ViewReport rep{views[k].name, false, -1, ""};
    if (!views[k].detection.found) {
      rep.note = views[k].detection.why_not;
      ++without_grid;
    } else if (std::make_pair(views[k].width, views[k].height) != size) {
      rep.note = "size " + std::to_string(views[k].width) + "x" + std::to_string(views[k].height) +
                 " differs from the set's " + std::to_string(size.first) + "x" + std::to_string(size.second);
      ++other_size;
    } else {
      candidates.push_back(k);
    }
    r.views.push_back(rep);
  }
  if (candidates.size() < o.min_views)
    throw std::invalid_argument(std::to_string(candidates.size()) + " of " + std::to_string(views.size()) +
                                " images are usable (" + std::to_string(without_grid) +
                                " without the grid, " + std::to_string(other_size) +
                                " of another size); at least " + std::to_string(o.min_views) + " are needed");
  if (other_size)
    r.notes.push_back(std::to_string(other_size) + " images of another size than " +
                      std::to_string(size.first) + "x" + std::to_string(size.second) + " left out");

  std::vector<cv::Point3f> board;
  for (const auto& p : grid.board_points())
    board.emplace_back(static_cast<float>(p.x()), static_cast<float>(p.y()), static_cast<float>(p.z()));
  const auto run = [&](const std::vector<size_t>& use) {
    std::vector<std::vector<cv::Point3f>> object(use.size(), board);
    std::vector<std::vector<cv::Point2f>> image;
    for (size_t k : use) {
      image.emplace_back();
      for (const auto& c : views[k].detection.centres)
        image.back().emplace_back(static_cast<float>(c.x()), static_cast<float>(c.y()));
    }
    return solve(object, image, cv::Size(size.first, size.second), o.model);
  };
  Solve s = run(candidates);
  // Views whose error is an outlier against the others' are left out, and the camera is calibrated again.
  const double bound = io::robust_upper_bound(s.per_view_rms, o.outlier_k, 0.5);
  std::vector<size_t> kept;
  for (size_t k = 0; k < candidates.size(); ++k) {
    if (s.per_view_rms[k] <= bound) {
      kept.push_back(candidates[k]);
    } else {
      r.views[candidates[k]].rms_px = s.per_view_rms[k];
      char note[96];
      std::snprintf(note, sizeof note, "reprojection RMS %.3f px, above the outlier bound %.3f px",
                    s.per_view_rms[k], bound);
      r.views[candidates[k]].note = note;
    }
  }
  if (kept.size() != candidates.size() && kept.size() >= o.min_views)
    s = run(kept);
  else
    kept = candidates;
  for (size_t k = 0; k < kept.size(); ++k) {
    r.views[kept[k]].used = true;
    r.views[kept[k]].rms_px = s.per_view_rms[k];
    r.views[kept[k]].note.clear();
  }
  r.views_used = kept.size();
  r.rms_px = s.rms;
  r.stddev = s.stddev;
  r.camera.model = o.model;
  r.camera.width = size.first;
  r.camera.height = size.second;
  r.camera.fx = s.K(0, 0);
  r.camera.fy = s.K(1, 1);
  r.camera.cx = s.K(0, 2);
  r.camera.cy = s.K(1, 2);
  for (int k = 0; k < s.dist.cols; ++k) r.camera.distortion.push_back(s.dist.at<double>(0, k));
  // Coverage: which cells of an 8x8 grid over the image hold a detected centre of a view used.
  std::vector<char> cell(64, 0);
  for (size_t k : kept)
    for (const auto& c : views[k].detection.centres) {
      const int cx = std::clamp(static_cast<int>(c.x() * 8 / size.first), 0, 7);
      const int cy = std::clamp(static_cast<int>(c.y() * 8 / size.second), 0, 7);
      cell[static_cast<size_t>(cy * 8 + cx)] = 1;
    }
  r.coverage = static_cast<double>(std::count(cell.begin(), cell.end(), 1)) / 64.0;
  const char* corner_names[4] = {"top-left", "top-right", "bottom-left", "bottom-right"};
  const int corner_cells[4] = {0, 7, 56, 63};
  for (int k = 0; k < 4; ++k)
    if (!cell[static_cast<size_t>(corner_cells[k])])
      r.notes.push_back(std::string("no detection in the image's ") + corner_names[k] +
                        " corner: the distortion there is extrapolated");
  return r;
}

}  // namespace litgs::calib
