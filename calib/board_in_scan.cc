#include "calib/board_in_scan.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <numeric>
#include <opencv2/imgproc.hpp>
#include <stdexcept>

#include "calib/layout_fit.h"
#include "io/robust_stats.h"

namespace litgs::calib {
namespace {

constexpr double kDeg = M_PI / 180;
// Returns of one ring share their elevation; neighbouring rings of a VLP-32C are at least 0.33 degrees apart.
constexpr double kRingSplitRad = 0.1 * kDeg;

struct Ring {
  std::vector<size_t> points;  // sorted by azimuth
  std::vector<double> azimuth;
  double elevation = 0;
  double elevation_span = 0;  // highest minus lowest return's elevation
};

std::vector<Ring> split_rings(const std::vector<Eigen::Vector3d>& p, const BoardInScanOptions& o) {
  std::vector<size_t> idx;
  std::vector<double> el(p.size()), az(p.size());
  for (size_t i = 0; i < p.size(); ++i) {
    const double range = p[i].norm();
    if (!p[i].allFinite() || range < o.min_range_m || range > o.max_range_m) continue;
    el[i] = std::atan2(p[i].z(), p[i].head<2>().norm());
    az[i] = std::atan2(p[i].y(), p[i].x());
    idx.push_back(i);
  }
  std::sort(idx.begin(), idx.end(), [&](size_t a, size_t b) { return el[a] < el[b]; });
  std::vector<Ring> rings;
  for (size_t k = 0; k < idx.size(); ++k) {
    if (k == 0 || el[idx[k]] - el[idx[k - 1]] > kRingSplitRad) rings.emplace_back();
    rings.back().points.push_back(idx[k]);
    rings.back().elevation_span = el[idx[k]] - el[rings.back().points.front()];  // idx rises in elevation
  }
  for (Ring& r : rings) {
    std::sort(r.points.begin(), r.points.end(), [&](size_t a, size_t b) { return az[a] < az[b]; });
    for (size_t i : r.points) r.azimuth.push_back(az[i]);
    r.elevation = el[r.points[r.points.size() / 2]];
  }
  return rings;
}

struct UnionFind {
  std::vector<size_t> parent;
  explicit UnionFind(size_t n) : parent(n) { std::iota(parent.begin(), parent.end(), size_t{0}); }
  size_t find(size_t i) {
    while (parent[i] != i) i = parent[i] = parent[parent[i]];
    return i;
  }
  void join(size_t a, size_t b) { parent[find(a)] = find(b); }
};

// Segments: returns joined to their neighbours along a ring and to the nearest-azimuth return of the next
// ring when closer than a few beam spacings at their range.
std::vector<std::vector<size_t>> segments(const std::vector<Eigen::Vector3d>& p,
                                          const std::vector<Ring>& rings) {
  std::vector<double> ring_steps, az_steps;
  for (size_t r = 1; r < rings.size(); ++r) ring_steps.push_back(rings[r].elevation - rings[r - 1].elevation);
  for (const Ring& r : rings)
    for (size_t k = 1; k < r.azimuth.size(); ++k) az_steps.push_back(r.azimuth[k] - r.azimuth[k - 1]);
  const double step = std::max(io::median(ring_steps), io::median(az_steps));
  const auto near = [&](size_t a, size_t b) { return (p[a] - p[b]).norm() < 3 * step * p[a].norm() + 0.05; };
  UnionFind uf(p.size());
  for (size_t r = 0; r < rings.size(); ++r) {
    const Ring& ring = rings[r];
    for (size_t k = 1; k < ring.points.size(); ++k)
      if (near(ring.points[k - 1], ring.points[k])) uf.join(ring.points[k - 1], ring.points[k]);
    if (r + 1 == rings.size()) continue;
    const Ring& up = rings[r + 1];
    for (size_t k = 0; k < ring.points.size(); ++k) {
      const auto it = std::lower_bound(up.azimuth.begin(), up.azimuth.end(), ring.azimuth[k]);
      for (auto j : {it, it == up.azimuth.begin() ? it : it - 1}) {
        if (j == up.azimuth.end()) continue;
        const size_t q = up.points[static_cast<size_t>(j - up.azimuth.begin())];
        if (near(ring.points[k], q)) uf.join(ring.points[k], q);
      }
    }
  }
  std::vector<std::vector<size_t>> by_root(p.size());
  for (const Ring& ring : rings)
    for (size_t i : ring.points) by_root[uf.find(i)].push_back(i);
  std::vector<std::vector<size_t>> out;
  for (auto& s : by_root)
    if (s.size() >= 30) out.push_back(std::move(s));
  return out;
}

// The board's frame fitted to a segment: origin at its centroid, z the normal away from the sensor, y the
// LiDAR's down within the plane, x = y cross z (right as seen from the sensor).
struct PlaneFrame {
  Eigen::Vector3d origin = Eigen::Vector3d::Zero(), x = Eigen::Vector3d::UnitX(),
                  y = Eigen::Vector3d::UnitY(), z = Eigen::Vector3d::UnitZ();
  double rms_m = 0;
  Eigen::Vector2d to_2d(const Eigen::Vector3d& q) const { return {(q - origin).dot(x), (q - origin).dot(y)}; }
  Eigen::Vector3d to_3d(const Eigen::Vector2d& q) const { return origin + q.x() * x + q.y() * y; }
};

bool fit_plane_frame(const std::vector<Eigen::Vector3d>& p, const std::vector<size_t>& idx, PlaneFrame& f) {
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (size_t i : idx) mean += p[i];
  mean /= static_cast<double>(idx.size());
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  for (size_t i : idx) cov += (p[i] - mean) * (p[i] - mean).transpose();
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es(cov);
  Eigen::Vector3d n = es.eigenvectors().col(0);
  if (n.dot(mean) < 0) n = -n;
  const Eigen::Vector3d down = -Eigen::Vector3d::UnitZ();
  Eigen::Vector3d y = down - down.dot(n) * n;
  if (y.norm() < 0.7) return false;  // the plane is within 45 degrees of horizontal
  f.origin = mean;
  f.z = n;
  f.y = y.normalized();
  f.x = f.y.cross(f.z);
  f.rms_m = std::sqrt(std::max(0.0, es.eigenvalues()(0)) / static_cast<double>(idx.size()));
  return true;
}

}  // namespace

void BoardInScanOptions::check() const {
  if (!(beam_divergence_rad >= 0 && beam_divergence_rad < 0.1))
    throw std::invalid_argument("beam divergence must be in [0, 0.1) rad");
  if (!(min_range_m >= 0 && max_range_m > min_range_m))
    throw std::invalid_argument("board search ranges: need 0 <= min < max");
}

BoardInScan find_board_in_scan(const std::vector<Eigen::Vector3d>& p, const HoledBoard& board,
                               const BoardInScanOptions& o) {
  board.check();
  o.check();
  BoardInScan out;
  const std::vector<Ring> rings = split_rings(p, o);
  if (rings.empty()) {
    out.why_not =
        "no returns within " + std::to_string(o.min_range_m) + "-" + std::to_string(o.max_range_m) + " m";
    return out;
  }
  // A spinning LiDAR's returns fall on a few dozen cones of one elevation each; a non-repetitive pattern's
  // (Livox) spread over the field of view.
  double widest = 0;
  for (const Ring& r : rings) widest = std::max(widest, r.elevation_span);
  if (rings.size() > 512 || widest > 1 * kDeg) {
    out.why_not = "the returns form no rings of one elevation each (" + std::to_string(rings.size()) +
                  " groups, the widest over " + std::to_string(static_cast<int>(std::ceil(widest / kDeg))) +
                  " degrees): a spinning LiDAR's scan is needed";
    return out;
  }
  // The board: the planar segment whose extent in its plane best matches the board's outline.
  const double big = std::max(board.width_m, board.height_m), small = std::min(board.width_m, board.height_m);
  double best_score = 0.25;
  std::vector<size_t> best;
  PlaneFrame frame;
  std::string seen;
  for (const auto& seg : segments(p, rings)) {
    PlaneFrame f;
    if (!fit_plane_frame(p, seg, f) || f.rms_m > 0.05) continue;
    std::vector<cv::Point2f> flat;
    for (size_t i : seg) {
      const Eigen::Vector2d q = f.to_2d(p[i]);
      flat.emplace_back(static_cast<float>(q.x()), static_cast<float>(q.y()));
    }
    const cv::RotatedRect box = cv::minAreaRect(flat);
    const double a = std::max(box.size.width, box.size.height), b = std::min(box.size.width, box.size.height);
    // Sparse rings shorten the extent across them by up to two ring spacings.
    const double score = std::max(std::abs(a / big - 1), std::abs(b / small - 1) * 0.6);
    if (seen.size() < 120)
      seen += (seen.empty() ? "" : ", ") + std::to_string(a).substr(0, 4) + "x" +
              std::to_string(b).substr(0, 4) + " m";
    if (score < best_score) {
      best_score = score;
      best = seg;
      frame = f;
    }
  }
  if (best.empty()) {
    out.why_not = "no planar segment of the board's size (" + std::to_string(board.width_m).substr(0, 4) +
                  "x" + std::to_string(board.height_m).substr(0, 4) + " m)" +
                  (seen.empty() ? "" : "; planar segments: " + seen);
    return out;
  }
  out.board_points = best.size();
  out.plane_rms_m = frame.rms_m;
  out.normal = frame.z;

  // Hole boundaries along each ring: a gap in the board's returns well over the ring's spacing.
  std::vector<char> on_board(p.size(), 0);
  for (size_t i : best) on_board[i] = 1;
  struct Gap {
    Eigen::Vector2d a, b, mid;
  };
  std::vector<Gap> gaps;
  // Each return placed where its ray meets the fitted plane: the ray's direction is exact, its range is not.
  const auto on_plane = [&](double elevation, double azimuth) {
    const Eigen::Vector3d dir(std::cos(elevation) * std::cos(azimuth),
                              std::cos(elevation) * std::sin(azimuth), std::sin(elevation));
    return frame.to_2d(dir * (frame.origin.dot(frame.z) / dir.dot(frame.z)));
  };
  for (const Ring& ring : rings) {
    std::vector<double> az;
    for (size_t k = 0; k < ring.points.size(); ++k)
      if (on_board[ring.points[k]]) az.push_back(ring.azimuth[k]);
    if (az.size() < 4) continue;
    std::vector<double> steps;
    for (size_t k = 1; k < az.size(); ++k) steps.push_back(az[k] - az[k - 1]);
    const double step = io::median(steps);
    // The edge lies past the last return by half a step on average, less the half divergence with which a
    // beam still touching the board returns from it.
    const double shift = step / 2 - o.beam_divergence_rad / 2;
    for (size_t k = 1; k < az.size(); ++k) {
      if (steps[k - 1] < 2.5 * step) continue;
      Gap g{on_plane(ring.elevation, az[k - 1] + shift), on_plane(ring.elevation, az[k] - shift), {}};
      g.mid = (g.a + g.b) / 2;
      gaps.push_back(g);
    }
  }
  // Gaps grouped by hole: midpoints within a radius of a group's mean.
  struct Group {
    Eigen::Vector2d sum = Eigen::Vector2d::Zero();
    std::vector<Eigen::Vector2d> boundary;
    int gaps = 0;
    Eigen::Vector2d mean() const { return sum / gaps; }
  };
  std::vector<Group> groups;
  for (const Gap& g : gaps) {
    Group* home = nullptr;
    for (Group& gr : groups)
      if ((gr.mean() - g.mid).norm() < 1.2 * board.hole_radius_m) home = &gr;
    if (!home) home = &groups.emplace_back();
    home->sum += g.mid;
    home->gaps += 1;
    home->boundary.push_back(g.a);
    home->boundary.push_back(g.b);
  }
  std::erase_if(groups, [](const Group& g) { return g.gaps < 2; });
  std::sort(groups.begin(), groups.end(), [](const Group& a, const Group& b) { return a.gaps > b.gaps; });
  if (groups.size() < board.holes.size()) {
    out.why_not = "found " + std::to_string(groups.size()) + " of the board's " +
                  std::to_string(board.holes.size()) + " holes crossed by two or more rings (" +
                  std::to_string(best.size()) + " board returns)";
    return out;
  }
  groups.resize(board.holes.size());
  // A circle of the hole's radius through each hole's boundary (Gauss-Newton on the distance to it).
  std::vector<Eigen::Vector2d> centres;
  for (const Group& g : groups) {
    Eigen::Vector2d c = Eigen::Vector2d::Zero();
    for (const auto& q : g.boundary) c += q;
    c /= static_cast<double>(g.boundary.size());
    for (int it = 0; it < 30; ++it) {
      Eigen::Matrix2d JtJ = Eigen::Matrix2d::Zero();
      Eigen::Vector2d Jtr = Eigen::Vector2d::Zero();
      for (const auto& q : g.boundary) {
        const Eigen::Vector2d d = c - q;
        const double len = std::max(d.norm(), 1e-9);
        const Eigen::Vector2d J = d / len;
        const double r = len - board.hole_radius_m;
        JtJ += J * J.transpose();
        Jtr += J * r;
      }
      const Eigen::Vector2d step = JtJ.ldlt().solve(-Jtr);
      c += step;
      if (step.norm() < 1e-7) break;
    }
    centres.push_back(c);
    out.boundary_points.push_back(static_cast<int>(g.boundary.size()));
  }
  const LayoutFit fit = fit_layout_2d(board.holes, centres);
  if (!fit.ok || fit.rms > 0.3 * board.hole_radius_m) {
    out.why_not =
        fit.ok ? "the holes found do not fit the board's layout (RMS " + std::to_string(fit.rms) + " m)"
               : fit.why_not;
    return out;
  }
  out.layout_rms_m = fit.rms;
  for (size_t k = 0; k < board.holes.size(); ++k) out.centres.push_back(frame.to_3d(fit.placed[k]));
  std::vector<int> boundary(board.holes.size());
  for (size_t k = 0; k < board.holes.size(); ++k) boundary[k] = out.boundary_points[fit.detection_of_hole[k]];
  out.boundary_points = boundary;
  out.found = true;
  return out;
}

}  // namespace litgs::calib
