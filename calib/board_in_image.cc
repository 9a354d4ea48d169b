#include "calib/board_in_image.h"

#include <algorithm>
#include <climits>
#include <cmath>
#include <limits>
#include <opencv2/calib3d.hpp>
#include <opencv2/core/eigen.hpp>
#include <opencv2/imgproc.hpp>

#include "calib/circle_grid.h"
#include "calib/layout_fit.h"
#include "io/lens_distortion.h"
#include "io/robust_stats.h"

namespace litgs::calib {
namespace {

// The hole's intensity-weighted centroid in the frame's own values: weights go from 0 at two noise sigmas
// past the board's level to 1 at half the way to the hole's (the median inside it), so the blur's spread of
// the edge keeps the centroid where it was (it is symmetric about the outline) and a background that differs
// across the hole (wall and ground) does not pull it. The board's level is a plane fitted to a ring of board
// around the hole: a gradient across the board (vignetting, a warmer side) would otherwise weigh one side's
// noise more.
bool hole_centroid(const cv::Mat& values, const std::vector<cv::Point>& contour, Eigen::Vector2d& centre) {
  const double area = cv::contourArea(contour);
  const int margin = std::max(2, static_cast<int>(std::lround(0.25 * std::sqrt(area / M_PI))));
  // Only the pixels around the hole: its bounding box grown past the window's reach (the margin's dilation),
  // so that every pixel the masks can mark lies inside; sums run over the same pixels in the same order.
  const cv::Rect box = cv::boundingRect(contour);
  const int pad = margin + 3;
  const cv::Rect roi = cv::Rect(box.x - pad, box.y - pad, box.width + 2 * pad, box.height + 2 * pad) &
                       cv::Rect(0, 0, values.cols, values.rows);
  cv::Mat hole = cv::Mat::zeros(roi.size(), CV_8U);
  cv::drawContours(hole, std::vector<std::vector<cv::Point>>{contour}, 0, 255, cv::FILLED, cv::LINE_8,
                   cv::noArray(), INT_MAX, cv::Point(-roi.x, -roi.y));
  cv::Mat inner, near, window;
  cv::erode(hole, inner, cv::Mat(), cv::Point(-1, -1), 2);
  cv::dilate(hole, near, cv::Mat(), cv::Point(-1, -1), 2);
  cv::dilate(hole, window,
             cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(2 * margin + 1, 2 * margin + 1)));
  // Calls f(x, y) for each window pixel, in image coordinates, row by row.
  const auto for_window = [&](auto&& f) {
    for (int r = 0; r < roi.height; ++r)
      for (int c = 0; c < roi.width; ++c)
        if (window.at<uint8_t>(r, c))
          f(c + roi.x, r + roi.y, inner.at<uint8_t>(r, c) != 0, near.at<uint8_t>(r, c) != 0);
  };
  std::vector<double> inside;
  Eigen::Matrix3d AtA = Eigen::Matrix3d::Zero();
  Eigen::Vector3d Atb = Eigen::Vector3d::Zero();
  size_t ring = 0;
  for_window([&](int x, int y, bool in, bool by) {
    if (in) inside.push_back(values.at<double>(y, x));
    if (!by) {
      const Eigen::Vector3d a(1, x, y);
      AtA += a * a.transpose();
      Atb += a * values.at<double>(y, x);
      ++ring;
    }
  });
  if (inside.empty() || ring < 12) return false;
  const Eigen::Vector3d board = AtA.ldlt().solve(Atb);
  const auto board_level = [&](int x, int y) { return board(0) + board(1) * x + board(2) * y; };
  const Eigen::Vector2d middle = Eigen::Vector2d(AtA(0, 1), AtA(0, 2)) / AtA(0, 0);
  const double contrast =
      io::median(inside) - board_level(static_cast<int>(middle.x()), static_cast<int>(middle.y()));
  // A dead band of two noise sigmas (the ring's spread about its plane), so that the board's own noise does
  // not weigh in and pull the centroid towards the window's centre.
  std::vector<double> spread;
  for_window([&](int x, int y, bool, bool by) {
    if (!by) spread.push_back(std::abs(values.at<double>(y, x) - board_level(x, y)));
  });
  // On a noisy frame the band stops at half the way to full weight, not to lose the hole.
  const double full = 0.5 * std::abs(contrast), floor = std::min(2 * 1.4826 * io::median(spread), 0.5 * full);
  if (!(full > 0)) return false;
  const double sign = contrast > 0 ? 1 : -1;
  double w = 0, sx = 0, sy = 0;
  for_window([&](int x, int y, bool, bool) {
    const double t =
        std::clamp((sign * (values.at<double>(y, x) - board_level(x, y)) - floor) / (full - floor), 0.0, 1.0);
    w += t;
    sx += t * x;
    sy += t * y;
  });
  if (!(w > 0)) return false;
  centre = {sx / w, sy / w};
  return true;
}

std::vector<cv::Point2d> undistorted(const io::CameraIntrinsics& K, const std::vector<Eigen::Vector2d>& px) {
  std::vector<cv::Point2d> out;
  for (const auto& p : px) {
    const auto u = io::undistort_normalized(K, {(p.x() - K.cx) / K.fx, (p.y() - K.cy) / K.fy});
    if (!u) return {};
    out.emplace_back(u->x(), u->y());
  }
  return out;
}

Eigen::Isometry3d to_isometry(const cv::Mat& rvec, const cv::Mat& tvec) {
  cv::Mat R;
  cv::Rodrigues(rvec, R);
  Eigen::Matrix3d r;
  cv::cv2eigen(R, r);
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = r;
  T.translation() = Eigen::Vector3d(tvec.at<double>(0), tvec.at<double>(1), tvec.at<double>(2));
  return T;
}

double rms_px(const io::CameraIntrinsics& K, const Eigen::Isometry3d& T,
              const std::vector<Eigen::Vector3d>& board, const std::vector<Eigen::Vector2d>& px) {
  double sq = 0;
  for (size_t k = 0; k < board.size(); ++k) sq += (project_to_pixel(K, T * board[k]) - px[k]).squaredNorm();
  return std::sqrt(sq / static_cast<double>(board.size()));
}

// Where the centroid of hole k's image lies against the projection of its centre: the hole's outline
// projected through the pose and the lens, its area centroid (shoelace) minus the centre's projection.
Eigen::Vector2d centroid_offset(const io::CameraIntrinsics& K, const Eigen::Isometry3d& T,
                                const HoledBoard& board, size_t k) {
  constexpr int kSamples = 180;
  std::vector<Eigen::Vector2d> outline;
  for (int i = 0; i < kSamples; ++i) {
    const double a = 2 * M_PI * i / kSamples;
    const Eigen::Vector3d q(board.holes[k].x() + board.hole_radius_m * std::cos(a),
                            board.holes[k].y() + board.hole_radius_m * std::sin(a), 0);
    outline.push_back(project_to_pixel(K, T * q));
  }
  double area = 0, cx = 0, cy = 0;
  for (int i = 0; i < kSamples; ++i) {
    const Eigen::Vector2d& a = outline[i];
    const Eigen::Vector2d& b = outline[(i + 1) % kSamples];
    const double cross = a.x() * b.y() - b.x() * a.y();
    area += cross;
    cx += (a.x() + b.x()) * cross;
    cy += (a.y() + b.y()) * cross;
  }
  const Eigen::Vector2d centroid(cx / (3 * area), cy / (3 * area));
  return centroid - project_to_pixel(K, T * Eigen::Vector3d(board.holes[k].x(), board.holes[k].y(), 0));
}

}  // namespace

Eigen::Vector2d project_to_pixel(const io::CameraIntrinsics& K, const Eigen::Vector3d& p) {
  const Eigen::Vector2d d = io::distort_normalized(K, {p.x() / p.z(), p.y() / p.z()});
  return {K.fx * d.x() + K.cx, K.fy * d.y() + K.cy};
}

BoardInImage find_board_in_image(const io::Image& image, const io::CameraIntrinsics& K,
                                 const HoledBoard& board) {
  board.check();
  BoardInImage out;
  if (image.width != K.width || image.height != K.height) {
    out.why_not = "image " + std::to_string(image.width) + "x" + std::to_string(image.height) +
                  ", intrinsics " + std::to_string(K.width) + "x" + std::to_string(K.height);
    return out;
  }
  const io::Image eight = thermal_8bit(image);
  const cv::Mat gray(eight.height, eight.width, CV_8U);
  for (size_t i = 0; i < eight.data.size(); ++i) gray.data[i] = static_cast<uint8_t>(eight.data[i]);
  cv::Mat high;
  cv::threshold(gray, high, 0, 255, cv::THRESH_BINARY | cv::THRESH_OTSU);
  const size_t n = board.holes.size();
  // The board: the largest region of one side of the threshold with at least n inner contours (holes).
  std::vector<std::vector<cv::Point>> best_holes;
  double best_area = 0;
  std::string tried;
  for (const bool warm : {true, false}) {
    cv::Mat mask = warm ? high : cv::Mat(255 - high);
    std::vector<std::vector<cv::Point>> contours;
    std::vector<cv::Vec4i> tree;
    cv::findContours(mask, contours, tree, cv::RETR_CCOMP, cv::CHAIN_APPROX_NONE);
    size_t most = 0;
    for (size_t i = 0; i < contours.size(); ++i) {
      if (tree[i][3] >= 0) continue;  // an inner contour
      std::vector<std::vector<cv::Point>> holes;
      for (int c = tree[i][2]; c >= 0; c = tree[c][0])
        if (cv::contourArea(contours[c]) >= 12) holes.push_back(contours[c]);
      most = std::max(most, holes.size());
      if (holes.size() < n) continue;
      std::sort(holes.begin(), holes.end(),
                [](const auto& a, const auto& b) { return cv::contourArea(a) > cv::contourArea(b); });
      holes.resize(n);
      if (cv::contourArea(holes.front()) > 6 * cv::contourArea(holes.back())) continue;
      const double area = cv::contourArea(contours[i]);
      if (area > best_area) {
        best_area = area;
        best_holes = holes;
        out.polarity = warm ? "warm board" : "cold board";
      }
    }
    tried += std::string(tried.empty() ? "" : ", ") + (warm ? "warm" : "cold") + " regions with at most " +
             std::to_string(most) + " holes";
  }
  if (best_holes.empty()) {
    out.why_not = "no board with " + std::to_string(n) + " holes (" + tried + ")";
    return out;
  }
  cv::Mat values(image.height, image.width, CV_64F);  // the frame's own values, not the 8-bit stretch
  for (int y = 0; y < image.height; ++y)
    for (int x = 0; x < image.width; ++x) values.at<double>(y, x) = image.at(x, y);
  std::vector<Eigen::Vector2d> centroids(n);
  for (size_t k = 0; k < n; ++k)
    if (!hole_centroid(values, best_holes[k], centroids[k])) {
      out.why_not = "a hole without contrast against the board";
      return out;
    }
  // The correspondence: the cyclic shift whose pose reprojects best; on a symmetric board the most upright.
  const std::vector<Eigen::Vector3d> on_board = board.hole_centres();
  std::vector<cv::Point3d> object;
  for (const auto& q : on_board) object.emplace_back(q.x(), q.y(), q.z());
  const cv::Mat identity = cv::Mat::eye(3, 3, CV_64F);
  const std::vector<cv::Point2d> rays = undistorted(K, centroids);
  if (rays.empty()) {
    out.why_not = "a hole centre outside the lens model's range";
    return out;
  }
  struct Candidate {
    std::vector<Eigen::Vector2d> px;
    Eigen::Isometry3d T;
    double rms = 0;
  };
  std::vector<Candidate> candidates;
  double least = std::numeric_limits<double>::infinity();
  for (const auto& match : cyclic_correspondences(board.holes, centroids)) {
    Candidate c;
    std::vector<cv::Point2d> image_points;
    for (size_t k = 0; k < n; ++k) {
      c.px.push_back(centroids[match[k]]);
      image_points.push_back(rays[match[k]]);
    }
    cv::Mat rvec, tvec;
    if (!cv::solvePnP(object, image_points, identity, cv::noArray(), rvec, tvec, false, cv::SOLVEPNP_IPPE))
      continue;
    c.T = to_isometry(rvec, tvec);
    c.rms = rms_px(K, c.T, on_board, c.px);
    least = std::min(least, c.rms);
    candidates.push_back(c);
  }
  const Candidate* chosen = nullptr;
  for (const Candidate& c : candidates)
    if (c.rms <= 1.5 * least + 0.5 && (!chosen || c.T.linear()(1, 1) > chosen->T.linear()(1, 1))) chosen = &c;
  if (!chosen) {
    out.why_not = "no board pose fits the holes";
    return out;
  }
  // The centroids moved onto the centres' projections, and the pose solved again.
  const std::vector<Eigen::Vector2d> measured = chosen->px;
  Eigen::Isometry3d T = chosen->T;
  std::vector<Eigen::Vector2d> corrected = measured;
  for (int pass = 0; pass < 3; ++pass) {
    for (size_t k = 0; k < n; ++k) corrected[k] = measured[k] - centroid_offset(K, T, board, k);
    const std::vector<cv::Point2d> image_points = undistorted(K, corrected);
    if (image_points.empty()) break;
    cv::Mat R(3, 3, CV_64F), rvec, tvec(3, 1, CV_64F);
    cv::eigen2cv(Eigen::Matrix3d(T.linear()), R);
    cv::Rodrigues(R, rvec);
    for (int i = 0; i < 3; ++i) tvec.at<double>(i) = T.translation()(i);
    cv::solvePnP(object, image_points, identity, cv::noArray(), rvec, tvec, true, cv::SOLVEPNP_ITERATIVE);
    T = to_isometry(rvec, tvec);
  }
  out.centres_px = corrected;
  out.T_cam_board = T;
  out.pnp_rms_px = rms_px(K, T, on_board, corrected);
  out.found = true;
  return out;
}

}  // namespace litgs::calib
