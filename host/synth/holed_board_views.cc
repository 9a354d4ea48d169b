#include "host/synth/holed_board_views.h"

#include <cmath>
#include <cstdio>
#include <nlohmann/json.hpp>
#include <stdexcept>

#include "host/synth/geometry.h"
#include "host/synth/rng.h"
#include "io/atomic_file.h"
#include "io/image.h"
#include "io/lens_distortion.h"
#include "io/pcd.h"
#include "io/scene_yaml.h"

namespace litgs::host::synth {
namespace {

constexpr double kDeg = M_PI / 180;

// The rig stands 1.5 m above the ground with a wall 10 m ahead: what the camera and the LiDAR see through
// the holes and around the board.
World board_world(const HoledBoardViewOptions& o, const Eigen::Matrix3d& R_world_board,
                  const Eigen::Vector3d& centre) {
  World w;
  ThermalTexture board;
  board.base_raw = 3900;  // a board warmed above the room, as in practice
  board.noise_raw = 3;
  board.noise_scale_m = 0.2;
  const int board_texture = w.add_texture(board);
  const ThermalTexture wall = calibration_room_wall();
  const int wall_texture = w.add_texture(wall);
  ThermalTexture ground = wall;
  ground.base_raw = 3450;
  const int ground_texture = w.add_texture(ground);
  const calib::HoledBoard& b = o.board;
  Rect r;
  r.origin = centre + R_world_board * Eigen::Vector3d(-b.width_m / 2, -b.height_m / 2, 0);
  r.u_axis = R_world_board.col(0);
  r.v_axis = R_world_board.col(1);
  r.u_len_m = b.width_m;
  r.v_len_m = b.height_m;
  for (const Eigen::Vector2d& h : b.holes)
    r.round_holes.push_back({h.x() + b.width_m / 2, h.y() + b.height_m / 2, b.hole_radius_m});
  r.texture = board_texture;
  w.add_rect(r);
  Rect back;  // facing the rig
  back.origin = Eigen::Vector3d(10, 20, -1.5);
  back.u_axis = -Eigen::Vector3d::UnitY();
  back.v_axis = Eigen::Vector3d::UnitZ();
  back.u_len_m = 40;
  back.v_len_m = 20;
  back.texture = wall_texture;
  w.add_rect(back);
  Rect floor;
  floor.origin = Eigen::Vector3d(-10, -20, -1.5);
  floor.u_axis = Eigen::Vector3d::UnitX();
  floor.v_axis = Eigen::Vector3d::UnitY();
  floor.u_len_m = 20;
  floor.v_len_m = 40;
  floor.texture = ground_texture;
  w.add_rect(floor);
  w.build_index();
  return w;
}

}  // namespace

LidarOptions HoledBoardViewOptions::velodyne_like() {
  LidarOptions l;
  l.beams = 32;
  l.fov_down_deg = -25;
  l.fov_up_deg = 15;
  l.columns = 1800;
  l.range_noise_m = 0.01;
  l.beam_divergence_rad = 0.003;
  return l;
}

Eigen::Isometry3d HoledBoardViewOptions::default_rig() {
  Eigen::Matrix3d look;  // camera x -> LiDAR -y, camera y -> LiDAR -z, camera z -> LiDAR x
  look << 0, 0, 1, -1, 0, 0, 0, -1, 0;
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = (Eigen::AngleAxisd(2.0 * kDeg, Eigen::Vector3d::UnitZ()) *
                Eigen::AngleAxisd(-1.5 * kDeg, Eigen::Vector3d::UnitY()) *
                Eigen::AngleAxisd(1.0 * kDeg, Eigen::Vector3d::UnitX()))
                   .toRotationMatrix() *
               look;
  T.translation() = Eigen::Vector3d(0.03, -0.10, -0.08);
  return T;
}

std::string HoledBoardViewOptions::check() const {
  if (const std::string c = camera.check(); !c.empty()) return c;
  if (const std::string c = lidar.check(); !c.empty()) return "lidar: " + c;
  if (lidar.pattern != LidarPattern::kSpinning) return "lidar: a spinning pattern is needed (rings)";
  try {
    board.check();
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  if (views < 1) return "views must be >= 1";
  if (!(min_distance_m > 0 && max_distance_m >= min_distance_m)) return "distances: 0 < min <= max";
  if (!(max_tilt_deg >= 0 && max_tilt_deg < 70)) return "max_tilt_deg must be in [0, 70)";
  return "";
}

std::vector<HoledBoardView> render_holed_board_views(const HoledBoardViewOptions& o, int threads) {
  if (const std::string c = o.check(); !c.empty()) throw std::invalid_argument("holed board views: " + c);
  const io::CameraIntrinsics K = o.camera.intrinsics();
  const calib::HoledBoard& b = o.board;
  Rng rng(o.seed, Stream::kCalibration);
  std::vector<HoledBoardView> out;
  int attempts = 0;
  while (static_cast<int>(out.size()) < o.views) {
    if (++attempts > 1000 * o.views)
      throw std::runtime_error("holed board views: no pose keeps the board in view");
    // The board's centre on a random pixel's ray, facing the camera within max_tilt, upright within 15
    // degrees.
    const double u = rng.uniform(0.3, 0.7) * K.width, v = rng.uniform(0.3, 0.7) * K.height;
    const double distance = rng.uniform(o.min_distance_m, o.max_distance_m);
    const Eigen::Vector3d ray_cam = Eigen::Vector3d((u - K.cx) / K.fx, (v - K.cy) / K.fy, 1).normalized();
    const Eigen::Vector3d centre = o.T_lidar_cam * (distance * ray_cam);
    const Eigen::Vector3d sight = (centre - o.T_lidar_cam.translation()).normalized();
    const double tilt = o.max_tilt_deg * kDeg * std::sqrt(rng.uniform());
    const Eigen::Vector3d axis = sight.unitOrthogonal();
    const Eigen::Vector3d z =
        Eigen::AngleAxisd(rng.uniform(0, 2 * M_PI), sight) * (Eigen::AngleAxisd(tilt, axis) * sight);
    // The world's down within the board's plane.
    Eigen::Vector3d y = (-Eigen::Vector3d::UnitZ() + z.z() * z).normalized();
    y = Eigen::AngleAxisd(rng.uniform(-15, 15) * kDeg, z) * y;
    Eigen::Matrix3d R;
    R << y.cross(z), y, z;
    // Inside the image with a margin, and between the LiDAR's lowest and highest rings.
    const Eigen::Isometry3d T_cam_lidar = o.T_lidar_cam.inverse();
    bool inside = true;
    for (const double sx : {-0.5, 0.5})
      for (const double sy : {-0.5, 0.5}) {
        const Eigen::Vector3d corner = centre + R * Eigen::Vector3d(sx * b.width_m, sy * b.height_m, 0);
        const Eigen::Vector3d c = T_cam_lidar * corner;
        const Eigen::Vector2d d = io::distort_normalized(K, {c.x() / c.z(), c.y() / c.z()});
        const double px = K.fx * d.x() + K.cx, py = K.fy * d.y() + K.cy;
        inside &= c.z() > 0.3 && px > 5 && py > 5 && px < K.width - 6 && py < K.height - 6;
        const double elevation = std::atan2(corner.z(), corner.head<2>().norm()) / kDeg;
        inside &= elevation > o.lidar.fov_down_deg + 1 && elevation < o.lidar.fov_up_deg - 1;
      }
    if (!inside) continue;
    const World world = board_world(o, R, centre);
    HoledBoardView view;
    view.raw = render_thermal(world, o.camera, o.T_lidar_cam, o.seed, out.size(), threads);
    Rng lidar_rng(o.seed, Stream::kLidar, out.size());
    view.scan =
        simulate_lidar_scan(world, Eigen::Isometry3d::Identity(), 0, 0, o.lidar, lidar_rng).points_lidar;
    Eigen::Isometry3d T_lidar_board = Eigen::Isometry3d::Identity();
    T_lidar_board.linear() = R;
    T_lidar_board.translation() = centre;
    view.T_cam_board = T_cam_lidar * T_lidar_board;
    out.push_back(std::move(view));
  }
  return out;
}

void write_holed_board_set(const std::filesystem::path& dir, const HoledBoardViewOptions& o, int threads) {
  const std::vector<HoledBoardView> views = render_holed_board_views(o, threads);
  std::filesystem::create_directories(dir / "images");
  std::filesystem::create_directories(dir / "scans");
  const io::CameraIntrinsics K = o.camera.intrinsics();
  const auto rows = [](const Eigen::Matrix4d& T) {
    nlohmann::json j = nlohmann::json::array();
    for (int r = 0; r < 4; ++r) j.push_back({T(r, 0), T(r, 1), T(r, 2), T(r, 3)});
    return j;
  };
  nlohmann::json truth = {{"T_cam_lidar", rows(o.T_lidar_cam.inverse().matrix())},
                          {"lidar",
                           {{"beams", o.lidar.beams},
                            {"columns", o.lidar.columns},
                            {"range_noise_m", o.lidar.range_noise_m},
                            {"beam_divergence_rad", o.lidar.beam_divergence_rad}}},
                          {"views", nlohmann::json::array()}};
  for (size_t i = 0; i < views.size(); ++i) {
    char name[32];
    std::snprintf(name, sizeof name, "view_%03zu", i);
    io::write_image(dir / "images" / (std::string(name) + ".png"), views[i].raw);
    io::PointCloud cloud;
    cloud.positions = views[i].scan;
    io::write_pcd(dir / "scans" / (std::string(name) + ".pcd"), cloud);
    truth["views"].push_back({{"name", name}, {"T_cam_board", rows(views[i].T_cam_board.matrix())}});
  }
  calib::write_holed_board(dir / "board.yaml", o.board);
  io::write_file_atomic(dir / "camera.yaml", [&](std::ostream& s) {
    s << "# The synthetic camera's true intrinsics\n" << io::camera_yaml_block(K);
  });
  io::write_file_atomic(dir / "truth.json", [&](std::ostream& s) { s << truth.dump(2) << "\n"; });
}

}  // namespace litgs::host::synth
