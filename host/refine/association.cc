#include "host/refine/association.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <nanoflann.hpp>
#include <optional>
#include <unordered_map>

#include "host/refine/triangulate_track.h"

namespace litgs::host::refine {
namespace {

// The pose as the rasterizer's camera (pixel centres at +0.5) for the map's depth image.
kernels::SplatCamera splat_camera(const CameraPose& pose, const PinholeCamera& c) {
  kernels::SplatCamera s;
  const Eigen::Matrix3d R = pose.q_world_cam.toRotationMatrix().transpose();
  const Eigen::Vector3d t = -R * pose.p_world_cam;
  for (int r = 0; r < 3; ++r)
    for (int k = 0; k < 3; ++k) s.R_cam_world[k][r] = R(r, k);  // glm is column-major
  s.t_cam_world = glm::dvec3(t.x(), t.y(), t.z());
  s.fx = c.fx;
  s.fy = c.fy;
  s.cx = c.cx + 0.5;
  s.cy = c.cy + 0.5;
  s.width = static_cast<uint32_t>(c.width);
  s.height = static_cast<uint32_t>(c.height);
  return s;
}

// Where x lands in the image, or false when behind the camera or outside.
bool project(const CameraPose& pose, const PinholeCamera& c, const Eigen::Vector3d& x, Eigen::Vector2d& uv,
             double& depth) {
  const Eigen::Vector3d q = pose.q_world_cam.conjugate() * (x - pose.p_world_cam);
  depth = q.z();
  if (q.z() <= 0.05) return false;
  uv = {c.fx * q.x() / q.z() + c.cx, c.fy * q.y() / q.z() + c.cy};
  return uv.x() >= -0.5 && uv.y() >= -0.5 && uv.x() < c.width - 0.5 && uv.y() < c.height - 0.5;
}

struct Adaptor {
  const std::vector<Eigen::Vector3d>* pts;
  size_t kdtree_get_point_count() const { return pts->size(); }
  double kdtree_get_pt(size_t i, size_t d) const { return (*pts)[i][static_cast<int>(d)]; }
  template <class B>
  bool kdtree_get_bbox(B&) const {
    return false;
  }
};
using Tree = nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<double, Adaptor>, Adaptor, 3>;

}  // namespace

AnchorAssociationReport associate_anchors(std::vector<TrackPoint>& points,
                                          const std::vector<AnchorPoint>& anchors,
                                          const std::vector<CameraPose>& poses, const PinholeCamera& camera,
                                          const PlanarMap* map, const AnchorAssociationOptions& o,
                                          size_t round) {
  AnchorAssociationReport report;
  for (auto& p : points) p.anchor = -1;
  const double radius =
      std::max(o.min_radius_px, o.radius_px * std::pow(o.shrink, static_cast<double>(round)));
  // Per frame, the observations by pixel cell for the radius search.
  const double cell = std::max(radius, 1.0);
  auto cell_key = [cell](const Eigen::Vector2d& uv) {
    return (static_cast<int64_t>(std::floor(uv.y() / cell)) << 32) ^
           static_cast<int64_t>(static_cast<uint32_t>(static_cast<int32_t>(std::floor(uv.x() / cell))));
  };
  std::vector<std::unordered_multimap<int64_t, size_t>> grid(poses.size());
  for (size_t k = 0; k < points.size(); ++k)
    for (const auto& ob : points[k].obs)
      if (points[k].active && ob.active && ob.frame < poses.size())
        grid[ob.frame].emplace(cell_key(ob.uv), k);

  std::vector<std::map<size_t, size_t>> votes(anchors.size());  // anchor -> track -> agreeing frames
  std::vector<std::map<size_t, double>> dist(anchors.size());   // anchor -> track -> summed pixel distance
  std::vector<std::vector<uint32_t>> visible(anchors.size());   // anchor -> frames that see it
  for (size_t f = 0; f < poses.size(); ++f) {
    std::optional<ViewPlaneMaps> depth;
    for (size_t a = 0; a < anchors.size(); ++a) {
      Eigen::Vector2d uv;
      double z = 0;
      if (!project(poses[f], camera, anchors[a].p_world, uv, z)) continue;
      if (map) {
        if (!depth) depth = project_planes(*map, splat_camera(poses[f], camera));
        const size_t px = static_cast<size_t>(std::floor(uv.x() + 0.5)),
                     py = static_cast<size_t>(std::floor(uv.y() + 0.5));
        const size_t i = 4 * (py * static_cast<size_t>(camera.width) + px);
        if (px < static_cast<size_t>(camera.width) && py < static_cast<size_t>(camera.height) &&
            depth->points[i + 3] > 0 && z > depth->points[i + 2] + o.occlusion_margin_m) {
          ++report.occluded_projections;
          continue;
        }
      }
      visible[a].push_back(static_cast<uint32_t>(f));
      // Every track seen in this frame near the anchor's projection votes.
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          const auto range = grid[f].equal_range(cell_key(uv + Eigen::Vector2d(dx * cell, dy * cell)));
          for (auto it = range.first; it != range.second; ++it)
            for (const auto& ob : points[it->second].obs)
              if (ob.frame == f && ob.active && (ob.uv - uv).norm() <= radius) {
                ++votes[a][it->second];
                dist[a][it->second] += (ob.uv - uv).norm();
              }
        }
    }
  }
  // Each track to its strongest agreeing anchor, each anchor to one track.
  std::vector<std::tuple<size_t, double, size_t, size_t>> pairs;  // votes, -mean distance, anchor, track
  for (size_t a = 0; a < anchors.size(); ++a) {
    if (!votes[a].empty()) ++report.anchors_in_view;
    const size_t first = pairs.size();
    for (const auto& [track, n] : votes[a]) {
      size_t shared = 0;  // frames that see the anchor and observe the track
      for (const auto& ob : points[track].obs)
        shared += ob.active && std::binary_search(visible[a].begin(), visible[a].end(), ob.frame);
      // The track's own point, triangulated again from its observations: the refined X of a track that
      // held this anchor in the previous round was pulled to it and would confirm itself.
      if (n < o.min_agreeing || 2 * n < shared) continue;
      const auto X = triangulate(points[track].obs, poses, camera);
      if (!X) continue;
      const Eigen::Vector3d e = *X - anchors[a].p_world;
      if (e.dot(anchors[a].cov.ldlt().solve(e)) <= o.gate_chi2)  // NaN fails too
        pairs.emplace_back(n, -dist[a][track] / static_cast<double>(n), a, track);
    }
    if (o.reject_ambiguous && pairs.size() > first + 1) {
      pairs.resize(first);
      ++report.ambiguous_anchors;
    }
  }
  std::sort(pairs.rbegin(), pairs.rend());
  std::vector<bool> anchor_used(anchors.size(), false);
  for (const auto& [n, neg_dist, a, track] : pairs) {
    if (anchor_used[a] || points[track].anchor >= 0) continue;
    anchor_used[a] = true;
    points[track].anchor = static_cast<int>(a);
    ++report.anchored_tracks;
  }
  return report;
}

struct PlaneAssociator::Impl {
  const PlanarMap& map;
  PinholeCamera camera;
  std::vector<Eigen::Vector3d> planar;  // planar map points
  std::vector<size_t> index;            // their index in the map
  Adaptor adaptor{&planar};
  std::unique_ptr<Tree> tree;
};

PlaneAssociator::PlaneAssociator(const PlanarMap& map, const PinholeCamera& camera)
    : impl_(new Impl{map, camera, {}, {}, {}, {}}) {
  for (size_t i = 0; i < map.points.size(); ++i)
    if (map.planar[i]) {
      impl_->planar.push_back(map.points[i].cast<double>());
      impl_->index.push_back(i);
    }
  impl_->adaptor.pts = &impl_->planar;
  impl_->tree = std::make_unique<Tree>(3, impl_->adaptor, nanoflann::KDTreeSingleIndexAdaptorParams(10));
  if (!impl_->planar.empty()) impl_->tree->buildIndex();
}

PlaneAssociator::~PlaneAssociator() = default;

PlaneAssociationReport PlaneAssociator::associate(std::vector<TrackPoint>& points,
                                                  const std::vector<CameraPose>& poses, size_t round,
                                                  const PlaneAssociationOptions& o) const {
  PlaneAssociationReport report;
  report.radius_m = std::max(o.min_radius_m, o.radius_m * std::pow(o.shrink, static_cast<double>(round)));
  const PlanarMap& map = impl_->map;
  const PinholeCamera& c = impl_->camera;
  std::map<size_t, ViewPlaneMaps> depth;  // per frame, made when first needed
  for (auto& p : points) {
    p.has_plane = false;
    if (!p.active || p.plane_rejected) continue;
    std::vector<const Observation*> active;
    for (const auto& ob : p.obs)
      if (ob.active) active.push_back(&ob);
    if (active.empty()) continue;
    PlaneRef plane;
    bool found = false;
    if (active.size() < o.long_track) {
      const Observation& ob = *active[active.size() / 2];
      auto it = depth.find(ob.frame);
      if (it == depth.end())
        it = depth.emplace(ob.frame, project_planes(map, splat_camera(poses[ob.frame], c))).first;
      const size_t px = static_cast<size_t>(std::floor(ob.uv.x() + 0.5)),
                   py = static_cast<size_t>(std::floor(ob.uv.y() + 0.5));
      if (px < static_cast<size_t>(c.width) && py < static_cast<size_t>(c.height)) {
        const size_t i = 4 * (py * static_cast<size_t>(c.width) + px);
        if (it->second.points[i + 3] > 0) {
          const CameraPose& pose = poses[ob.frame];
          const Eigen::Vector3d q(it->second.points[i], it->second.points[i + 1], it->second.points[i + 2]);
          const Eigen::Vector3d n(it->second.normals[i], it->second.normals[i + 1],
                                  it->second.normals[i + 2]);
          plane.n = (pose.q_world_cam * n).normalized();
          plane.l = pose.q_world_cam * q + pose.p_world_cam;
          found = true;
          ++report.by_depth_image;
        }
      }
    } else if (!impl_->planar.empty()) {
      uint32_t idx = 0;
      double d2 = 0;
      if (impl_->tree->knnSearch(p.X.data(), 1, &idx, &d2) == 1 && d2 <= report.radius_m * report.radius_m) {
        const size_t m = impl_->index[idx];
        plane.n = map.normals[m].cast<double>().normalized();
        plane.l = map.centres[m].cast<double>();
        found = true;
        ++report.by_nearest_point;
      }
    }
    if (found && std::abs(plane.n.dot(p.X - plane.l)) <= report.radius_m) {
      p.has_plane = true;
      p.plane = plane;
    } else {
      if (found) (active.size() < o.long_track ? report.by_depth_image : report.by_nearest_point)--;
      ++report.unassociated;
    }
  }
  return report;
}

}  // namespace litgs::host::refine
