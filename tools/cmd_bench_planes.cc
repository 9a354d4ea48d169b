// `litgs-engine bench planes --points FILE [--truth-planes planes.txt --truth-map gt/map.pcd] [--k K]`:
// the per-point plane fits of the LiDAR map, ours (nanoflann k-NN + PCA, host/train/lidar_planes.cc) against
// PCL's NormalEstimation with the same neighbourhood: seconds, and the normals' angular error against the
// true planes where a synthetic scene gives them (gt/map.pcd's plane_id, point for point). The only PCL
// translation unit.
#include <pcl/features/normal_3d.h>
#include <pcl/point_types.h>
#include <pcl/search/kdtree.h>

#include <CLI/CLI.hpp>
#include <chrono>
#include <cmath>
#include <iomanip>
#include <iostream>

#include "host/train/lidar_planes.h"
#include "io/pcd.h"
#include "io/ply_points.h"
#include "io/scene_text.h"
#include "tools/commands.h"

namespace litgs::tools {
namespace {

io::PointCloud read_points(const std::filesystem::path& p) {
  return p.extension() == ".ply" ? io::read_ply_points(p) : io::read_pcd(p);
}

struct AngleStats {
  double median_deg = 0, p90_deg = 0;
  size_t count = 0;
};

AngleStats angle_stats(std::vector<double> a) {
  AngleStats s;
  s.count = a.size();
  if (a.empty()) return s;
  std::sort(a.begin(), a.end());
  s.median_deg = a[a.size() / 2];
  s.p90_deg = a[a.size() * 9 / 10];
  return s;
}

double angle_deg(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return std::acos(std::min(1.0, std::abs(a.normalized().dot(b.normalized())))) * 180 / M_PI;
}

}  // namespace

void add_bench_planes_command(CLI::App& bench) {
  CLI::App* c = bench.add_subcommand("planes", "LiDAR plane fits: ours (nanoflann) against PCL's normals");
  auto points = std::make_shared<std::filesystem::path>();
  auto planes_path = std::make_shared<std::filesystem::path>();
  auto truth_map = std::make_shared<std::filesystem::path>();
  auto k = std::make_shared<uint32_t>(12);
  c->add_option("--points", *points, "Point cloud (.pcd or .ply)")->required()->check(CLI::ExistingFile);
  c->add_option("--truth-planes", *planes_path, "gt/planes.txt of a synthetic scene");
  c->add_option("--truth-map", *truth_map, "gt/map.pcd (plane_id per point of --points)");
  c->add_option("--k", *k, "Neighbours per fit")->capture_default_str();
  c->callback([points, planes_path, truth_map, k] {
    const io::PointCloud cloud = read_points(*points);
    host::PlaneFitOptions o;
    o.neighbours = *k;
    auto t0 = std::chrono::steady_clock::now();
    const host::PlanarMap ours = host::fit_planes(cloud.positions, o);
    const double ours_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();

    pcl::PointCloud<pcl::PointXYZ>::Ptr pc(new pcl::PointCloud<pcl::PointXYZ>);
    for (const auto& p : cloud.positions)
      pc->push_back(
          pcl::PointXYZ(static_cast<float>(p.x()), static_cast<float>(p.y()), static_cast<float>(p.z())));
    t0 = std::chrono::steady_clock::now();
    pcl::NormalEstimation<pcl::PointXYZ, pcl::Normal> ne;
    ne.setInputCloud(pc);
    ne.setSearchMethod(pcl::search::KdTree<pcl::PointXYZ>::Ptr(new pcl::search::KdTree<pcl::PointXYZ>));
    ne.setKSearch(static_cast<int>(*k));
    pcl::PointCloud<pcl::Normal> normals;
    ne.compute(normals);
    const double pcl_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();

    std::vector<double> agree, ours_err, pcl_err;
    std::vector<io::Plane> planes;
    const io::ScalarField* ids = nullptr;
    io::PointCloud gt;
    if (!planes_path->empty() && !truth_map->empty()) {
      planes = io::read_planes(*planes_path);
      gt = io::read_pcd(*truth_map);
      ids = gt.field("plane_id");
      if (!ids || gt.size() != cloud.size())
        throw std::invalid_argument(
            "--truth-map must be gt/map.pcd of the same scene (plane_id, same count)");
    }
    size_t pcl_valid = 0;
    for (size_t i = 0; i < cloud.size(); ++i) {
      const pcl::Normal& n = normals[i];
      const bool pv = std::isfinite(n.normal_x);
      pcl_valid += pv;
      if (!ours.planar[i] || !pv) continue;  // compare where our fit says planar
      const Eigen::Vector3d np(n.normal_x, n.normal_y, n.normal_z);
      agree.push_back(angle_deg(ours.normals[i].cast<double>(), np));
      if (ids && ids->values[i] >= 0) {
        const Eigen::Vector3d nt = planes.at(static_cast<size_t>(ids->values[i])).n;
        ours_err.push_back(angle_deg(ours.normals[i].cast<double>(), nt));
        pcl_err.push_back(angle_deg(np, nt));
      }
    }
    const AngleStats a = angle_stats(agree), eo = angle_stats(ours_err), ep = angle_stats(pcl_err);
    std::cout << std::fixed << std::setprecision(3) << "bench planes: " << cloud.size()
              << " points, k = " << *k << "\n  ours (nanoflann): " << ours_s << " s, " << ours.planar_count()
              << " planar"
              << "\n  PCL NormalEstimation: " << pcl_s << " s, " << pcl_valid << " normals"
              << "\n  ours vs PCL on our planar points: median " << a.median_deg << " deg, p90 " << a.p90_deg
              << " deg (" << a.count << ")\n";
    if (ids)
      std::cout << "  error vs true planes: ours median " << eo.median_deg << " deg, p90 " << eo.p90_deg
                << " deg; PCL median " << ep.median_deg << " deg, p90 " << ep.p90_deg << " deg (" << eo.count
                << " points)\n";
  });
}

}  // namespace litgs::tools
