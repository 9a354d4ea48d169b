#include "host/synth/circle_grid_views.h"

#include <cmath>
#include <nlohmann/json.hpp>
#include <stdexcept>

#include "host/synth/geometry.h"
#include "host/synth/rng.h"
#include "io/atomic_file.h"
#include "io/image.h"
#include "io/lens_distortion.h"

namespace litgs::host::synth {
namespace {

// The board's frame in the world: the world is the board frame itself (the board is the rectangle z = 0),
// with a margin of one spacing around the circles, and a uniform wall well behind it for the background.
World board_world(const CircleGridViewOptions& o) {
  World w;
  const CircleGridPattern& g = o.grid;
  const double margin = g.spacing_m;
  ThermalTexture board;
  board.pattern = ThermalPattern::kCircleGrid;
  board.base_raw = 3500;
  board.noise_raw = 2;
  board.noise_scale_m = 0.3;
  board.circles = g;
  board.circles.origin_u_m = margin;
  board.circles.origin_v_m = margin;
  board.circles.raw = o.hot_circles ? std::abs(g.raw) : -std::abs(g.raw);
  const int board_texture = w.add_texture(board);
  const int wall_texture = w.add_texture(calibration_room_wall());
  Rect r;
  r.origin = Eigen::Vector3d(-margin, -margin, 0);
  r.u_axis = Eigen::Vector3d::UnitX();
  r.v_axis = Eigen::Vector3d::UnitY();
  r.u_len_m = (2 * (g.cols - 1) + 1) * g.spacing_m + 2 * margin;
  r.v_len_m = (g.rows - 1) * g.spacing_m + 2 * margin;
  r.texture = board_texture;
  w.add_rect(r);
  Rect back;
  back.origin = Eigen::Vector3d(-20, -20, 3);
  back.u_len_m = back.v_len_m = 40;
  back.texture = wall_texture;
  w.add_rect(back);
  w.build_index();
  return w;
}

}  // namespace

std::string CircleGridViewOptions::check() const {
  if (const std::string c = camera.check(); !c.empty()) return c;
  if (grid.cols < 2 || grid.rows < 3) return "grid: at least 2 columns and 3 rows";
  if (!(grid.spacing_m > 0) || !(grid.radius_m > 0) || !(grid.radius_m < grid.spacing_m * 0.7))
    return "grid: spacing > 0 and 0 < radius < 0.7 spacing (neighbouring circles must not touch)";
  if (views < 1) return "views must be >= 1";
  if (!(min_distance_m > 0 && max_distance_m >= min_distance_m)) return "distances: 0 < min <= max";
  if (!(max_tilt_deg >= 0 && max_tilt_deg < 80)) return "max_tilt_deg must be in [0, 80)";
  return "";
}

std::vector<Eigen::Vector3d> circle_centres_on_board(const CircleGridPattern& g) {
  std::vector<Eigen::Vector3d> out;
  for (int i = 0; i < g.rows; ++i)
    for (int j = 0; j < g.cols; ++j) out.emplace_back((2 * j + i % 2) * g.spacing_m, i * g.spacing_m, 0.0);
  return out;
}

std::vector<CircleGridView> render_circle_grid_views(const CircleGridViewOptions& o, int threads) {
  if (const std::string c = o.check(); !c.empty()) throw std::invalid_argument("circle grid views: " + c);
  const World world = board_world(o);
  const io::CameraIntrinsics K = o.camera.intrinsics();
  const CircleGridPattern& g = o.grid;
  // The world is the board's frame: the first circle at the origin.
  const std::vector<Eigen::Vector3d> centres = circle_centres_on_board(g);
  const Eigen::Vector3d middle((2 * (g.cols - 1) + 1) * g.spacing_m / 2, (g.rows - 1) * g.spacing_m / 2, 0);
  Rng rng(o.seed, Stream::kCalibration);
  std::vector<CircleGridView> out;
  int attempts = 0;
  while (static_cast<int>(out.size()) < o.views) {
    if (++attempts > 1000 * o.views)
      throw std::runtime_error("circle grid views: no pose keeps the board in view");
    // The camera looks at a point near the board's centre from a direction within max_tilt of the normal.
    const double tilt = o.max_tilt_deg * M_PI / 180 * std::sqrt(rng.uniform());
    const double azimuth = rng.uniform(0, 2 * M_PI);
    const double distance = rng.uniform(o.min_distance_m, o.max_distance_m);
    const Eigen::Vector3d dir(std::sin(tilt) * std::cos(azimuth), std::sin(tilt) * std::sin(azimuth),
                              -std::cos(tilt));  // from the board towards the camera (the board faces -z)
    const Eigen::Vector3d target =
        middle + Eigen::Vector3d(rng.uniform(-0.05, 0.05), rng.uniform(-0.05, 0.05), 0);
    const Eigen::Vector3d eye = target + distance * dir;
    const Eigen::Vector3d z = (target - eye).normalized();
    const double roll = rng.uniform(-M_PI / 6, M_PI / 6);
    Eigen::Vector3d x = Eigen::Vector3d::UnitX() - z * z.x();
    x.normalize();
    x = Eigen::AngleAxisd(roll, z) * x;
    const Eigen::Vector3d y = z.cross(x);
    // Turned off the board's centre by up to 15 degrees, so that the views reach the image's corners.
    const Eigen::Matrix3d look = (Eigen::Matrix3d() << x, y, z).finished();
    const Eigen::Matrix3d turn = (Eigen::AngleAxisd(rng.uniform(-0.26, 0.26), Eigen::Vector3d::UnitX()) *
                                  Eigen::AngleAxisd(rng.uniform(-0.26, 0.26), Eigen::Vector3d::UnitY()))
                                     .toRotationMatrix();
    Eigen::Isometry3d T_world_cam = Eigen::Isometry3d::Identity();
    T_world_cam.linear() = look * turn;
    T_world_cam.translation() = eye;
    // Every circle inside the image, two radii from its border (in pixels at the circle's depth).
    const Eigen::Isometry3d T_cam_world = T_world_cam.inverse();
    bool inside = true;
    for (const auto& c : centres) {
      const Eigen::Vector3d p = T_cam_world * c;
      const double edge = 2 * g.radius_m * K.fx / p.z();
      const Eigen::Vector2d d = io::distort_normalized(K, {p.x() / p.z(), p.y() / p.z()});
      const double u = K.fx * d.x() + K.cx, v = K.fy * d.y() + K.cy;
      inside &= p.z() > 0 && u > edge && v > edge && u < K.width - 1 - edge && v < K.height - 1 - edge;
    }
    if (!inside) continue;
    CircleGridView view;
    view.raw = render_thermal(world, o.camera, T_world_cam, o.seed, out.size(), threads);
    view.T_cam_board = T_cam_world;
    out.push_back(std::move(view));
  }
  return out;
}

void write_circle_grid_set(const std::filesystem::path& dir, const CircleGridViewOptions& o, int threads) {
  const std::vector<CircleGridView> views = render_circle_grid_views(o, threads);
  std::filesystem::create_directories(dir / "images");
  const io::CameraIntrinsics K = o.camera.intrinsics();
  nlohmann::json truth = {{"camera",
                           {{"width", K.width},
                            {"height", K.height},
                            {"fx", K.fx},
                            {"fy", K.fy},
                            {"cx", K.cx},
                            {"cy", K.cy},
                            {"model", K.model == io::CameraModel::kPinhole ? "pinhole" : "equidistant"},
                            {"distortion", K.distortion}}},
                          {"grid",
                           {{"cols", o.grid.cols},
                            {"rows", o.grid.rows},
                            {"spacing_m", o.grid.spacing_m},
                            {"radius_m", o.grid.radius_m},
                            {"polarity", o.hot_circles ? "hot" : "cold"}}},
                          {"views", nlohmann::json::array()}};
  for (size_t i = 0; i < views.size(); ++i) {
    char name[32];
    std::snprintf(name, sizeof name, "view_%03zu.png", i);
    io::write_image(dir / "images" / name, views[i].raw);
    const Eigen::Matrix4d T = views[i].T_cam_board.matrix();
    nlohmann::json rows = nlohmann::json::array();
    for (int r = 0; r < 4; ++r) rows.push_back({T(r, 0), T(r, 1), T(r, 2), T(r, 3)});
    truth["views"].push_back({{"image", std::string("images/") + name}, {"T_cam_board", rows}});
  }
  io::write_file_atomic(dir / "truth.json", [&](std::ostream& s) { s << truth.dump(2) << "\n"; });
}

}  // namespace litgs::host::synth
