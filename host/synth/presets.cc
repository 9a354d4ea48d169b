#include "host/synth/presets.h"

#include <cmath>
#include <numbers>
#include <stdexcept>

#include "host/synth/rng.h"

namespace litgs::host::synth {
namespace {

using Eigen::Vector3d;
constexpr double kDeg = std::numbers::pi / 180;

// A camera mounted on the body looking towards yaw (left positive) and pitch (up positive), plus a small
// random mounting error: calibrated extrinsics are never axis-aligned.
Eigen::Isometry3d camera_mount(double yaw_rad, double pitch_rad, const Vector3d& t_imu_cam, Rng& rng) {
  const Vector3d z(std::cos(pitch_rad) * std::cos(yaw_rad), std::cos(pitch_rad) * std::sin(yaw_rad),
                   std::sin(pitch_rad));
  const Vector3d x = z.cross(Vector3d::UnitZ()).normalized();  // right
  const Vector3d y = z.cross(x);                               // down
  Eigen::Matrix3d R;
  R << x, y, z;
  const Vector3d err = 0.5 * kDeg * Vector3d(rng.normal(), rng.normal(), rng.normal());
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(err.norm(), err.normalized()).toRotationMatrix() * R;
  T.translation() = t_imu_cam;
  return T;
}

Eigen::Isometry3d lidar_mount(const Vector3d& t_imu_lidar, Rng& rng) {
  const Vector3d err = 0.3 * kDeg * Vector3d(rng.normal(), rng.normal(), rng.normal());
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(err.norm(), err.normalized()).toRotationMatrix();
  T.translation() = t_imu_lidar;
  return T;
}

// The radiances below are written relative to 3500 counts and shifted by this: the Workswell frames of
// the Thermitage DUNR set (a facade; tests/data/thermitage-dunr holds 3 of them) sit around 4000 counts
// (1st..99th percentile ~3900..4200), their sky near 3050.
constexpr double kSceneOffsetRaw = 550;

ThermalTexture uniform(double base, double noise, double scale_m, uint64_t seed) {
  ThermalTexture t;
  t.base_raw = base + kSceneOffsetRaw;
  t.noise_raw = noise;
  t.noise_scale_m = scale_m;
  t.seed = seed;
  return t;
}

ThermalTexture cells(ThermalPattern p, double base, double cu, double cv, double joint_m, double joint_raw,
                     double jitter, uint64_t seed) {
  ThermalTexture t = uniform(base, 2, 2, seed);
  t.pattern = p;
  t.cell_u_m = cu;
  t.cell_v_m = cv;
  t.joint_m = joint_m;
  t.joint_raw = joint_raw;
  t.cell_jitter_raw = jitter;
  return t;
}

// Ground as one big horizontal rectangle.
void add_ground(World& w, double x0, double y0, double x1, double y1, int texture) {
  w.add_rect({Vector3d(x0, y0, 0), Vector3d::UnitX(), Vector3d::UnitY(), x1 - x0, y1 - y0, {}, texture});
}

// Windows on `floors` floors every `spacing_m`, doors on the ground floor every `door_every` window slot.
std::vector<World::Opening> facade_openings(double length_m, int floors, double spacing_m, int door_every,
                                            int window_tex, int door_tex) {
  std::vector<World::Opening> out;
  int slot = 0;
  for (double u = 1.5; u + 1.5 < length_m; u += spacing_m, ++slot) {
    for (int f = 0; f < floors; ++f) {
      const double v0 = 0.9 + 3.2 * f;
      if (f == 0 && door_every > 0 && slot % door_every == 1)
        out.push_back({{u, 0.0, u + 1.2, 2.3}, 0.12, door_tex});
      else
        out.push_back({{u, v0, u + 1.4, v0 + 1.6}, 0.18, window_tex});
    }
  }
  return out;
}

// Heat leaking around each opening of a wall: a copy of the wall's texture with one halo per opening
// (windows warmer than doors). Returns the new texture's index.
int with_halos(World& w, int texture, const std::vector<World::Opening>& openings, double window_raw,
               double door_raw) {
  ThermalTexture t = w.textures[static_cast<size_t>(texture)];
  t.streak_raw = 25;  // runoff below sills and along the wall
  for (const World::Opening& o : openings) {
    const bool door = o.hole.v0_m <= 0.01;
    t.halos.push_back(
        {o.hole.u0_m, o.hole.v0_m, o.hole.u1_m, o.hole.v1_m, door ? door_raw : window_raw, door ? 0.2 : 0.3});
  }
  return w.add_texture(t);
}

// Wall with openings; with a textured appearance the openings leak heat into it.
void add_wall_with_openings(World& w, const Vector3d& start, double length_m, double height_m, int texture,
                            const std::vector<World::Opening>& openings, Appearance appearance) {
  if (appearance == Appearance::kTextured) texture = with_halos(w, texture, openings, 60, 35);
  w.add_wall(start, Vector3d::UnitX(), length_m, height_m, texture, openings, Vector3d(0, 0, 1));
}

// What makes real long-wave frames matchable (docs/synthetic-appearance.md): every surface gets weathering
// at five scales, cells (bricks, panels, tiles) spread more from one another, walls get rain streaks, and
// the camera blurs and has a column pattern. The amplitudes were chosen by comparing with the DUNR frames
// (`litgs-engine compare-frames`): gradient histogram, keypoints per image and inlier ratio.
void weather(Preset& p) {
  for (ThermalTexture& t : p.world.textures) {
    t.detail_octaves = 8;
    t.detail_scale_m = 2;
    t.detail_raw = 45;
    t.detail_gain = 0.9;
    if (t.pattern != ThermalPattern::kUniform) {
      t.cell_jitter_raw = 2.5 * t.cell_jitter_raw + 15;
      t.joint_raw *= 2;
    }
  }
  p.camera.blur_px = 0.5;
  p.camera.column_noise_raw = 2;
  p.camera.temporal_noise_raw = 10;
  p.camera.fixed_pattern_raw = 3;
}

Preset facade(uint64_t seed, Appearance appearance) {
  Preset p;
  p.name = "facade";
  p.description = "a long planar building front (plaster and brick) with windows and doors, low texture";
  World& w = p.world;
  w.sky_raw = 3030;
  const int ground = w.add_texture(cells(ThermalPattern::kPanel, 3600, 0.4, 0.4, 0.008, -4, 3, seed + 1));
  const int plaster = w.add_texture([&] {
    ThermalTexture t = uniform(3470, 3, 4, seed + 2);
    t.gradient_v_raw_per_m = 1.5;  // heat rising along the front
    return t;
  }());
  const int brick = w.add_texture(cells(ThermalPattern::kBrick, 3520, 0.25, 0.065, 0.012, -14, 6, seed + 3));
  const int glass = w.add_texture([&] {
    ThermalTexture t = uniform(3180, 4, 1, seed + 4);
    t.gradient_v_raw_per_m = -25;  // reflects colder sky higher up
    return t;
  }());
  const int door = w.add_texture(cells(ThermalPattern::kPanel, 3640, 0.5, 0.7, 0.02, -12, 5, seed + 5));
  const int box = w.add_texture([&] {
    ThermalTexture t = uniform(3850, 5, 0.5, seed + 6);
    t.spot_raw = 350;  // a transformer inside
    t.spot_u_m = 0.3;
    t.spot_v_m = 0.8;
    t.spot_radius_m = 0.3;
    return t;
  }());
  const int metal = w.add_texture(uniform(3330, 3, 1, seed + 7));

  add_ground(w, -25, -20, 65, 20, ground);
  // Plaster building with windows; the brick neighbour stands 0.4 m further forward, joined by a side wall.
  add_wall_with_openings(w, Vector3d(-15, 8, 0), 33, 12, plaster, facade_openings(33, 3, 3.5, 4, glass, door),
                         appearance);
  add_wall_with_openings(w, Vector3d(18, 7.6, 0), 30, 9, brick, facade_openings(30, 2, 4.0, 3, glass, door),
                         appearance);
  w.add_rect({Vector3d(18, 7.6, 0), Vector3d::UnitY(), Vector3d::UnitZ(), 0.4, 9, {}, brick});
  w.add_box(Vector3d(6, 7.35, 0), Vector3d(0.8, 0.5, 1.3), 0, box);
  w.cylinders.push_back({Eigen::Vector2d(12, 5.5), 0.08, 0, 5, metal});
  w.cylinders.push_back({Eigen::Vector2d(28, 5.5), 0.08, 0, 5, metal});

  p.trajectory.start_m = Vector3d(0, 0, 1.5);
  p.trajectory.heading_rad = 0;
  Rng rig(seed, Stream::kRig);
  p.T_imu_cam = camera_mount(90 * kDeg, 5 * kDeg, Vector3d(0.08, 0.06, 0.1), rig);  // looking at the front
  p.T_imu_lidar = lidar_mount(Vector3d(0.0, 0.0, 0.15), rig);
  p.frames = 60;
  p.max_frames = 380;  // 48 m of front at up to 1.8 m/s
  return p;
}

// The street's surfaces: asphalt, plaster, brick, glass, doors, warm and cold cars, metal posts, bins.
struct StreetTextures {
  int asphalt, plaster, brick, glass, door, warm_car, cold_car, metal, bin;
};

StreetTextures add_street_textures(World& w, uint64_t seed) {
  const int asphalt = w.add_texture(uniform(3650, 15, 1.5, seed + 1));
  const int plaster = w.add_texture(uniform(3480, 4, 5, seed + 2));
  const int brick = w.add_texture(cells(ThermalPattern::kBrick, 3530, 0.25, 0.065, 0.012, -14, 6, seed + 3));
  const int glass = w.add_texture([&] {
    ThermalTexture t = uniform(3170, 4, 1, seed + 4);
    t.gradient_v_raw_per_m = -25;
    return t;
  }());
  const int door = w.add_texture(cells(ThermalPattern::kPanel, 3640, 0.5, 0.7, 0.02, -12, 5, seed + 5));
  const int warm_car = w.add_texture([&] {
    ThermalTexture t = uniform(3700, 6, 0.5, seed + 6);
    t.spot_raw = 600;  // the engine of a car just parked
    t.spot_u_m = 0.6;
    t.spot_v_m = 0.7;
    t.spot_radius_m = 0.5;
    return t;
  }());
  const int cold_car = w.add_texture(uniform(3420, 5, 0.5, seed + 7));
  const int metal = w.add_texture(uniform(3330, 3, 1, seed + 8));
  const int bin = w.add_texture(uniform(3560, 4, 0.3, seed + 9));

  return {asphalt, plaster, brick, glass, door, warm_car, cold_car, metal, bin};
}

// One 160 m block of the street, starting at x = x0 - 20: its facades, parked cars, posts and a bin.
void add_street_block(World& w, double x0, const StreetTextures& t, Appearance appearance) {
  add_wall_with_openings(w, Vector3d(x0 - 20, 10, 0), 70, 14, t.plaster,
                         facade_openings(70, 4, 3.5, 5, t.glass, t.door), appearance);
  add_wall_with_openings(w, Vector3d(x0 + 50, 10, 0), 90, 10, t.brick,
                         facade_openings(90, 3, 4.0, 4, t.glass, t.door), appearance);
  add_wall_with_openings(w, Vector3d(x0 - 20, -10, 0), 160, 12, t.plaster,
                         facade_openings(160, 3, 3.8, 6, t.glass, t.door), appearance);
  w.add_box(Vector3d(x0 + 30, 7.2, 0), Vector3d(4.5, 1.8, 1.5), 0, t.warm_car);
  w.add_box(Vector3d(x0 + 62, -7.0, 0), Vector3d(4.5, 1.8, 1.5), 0.05, t.cold_car);
  w.add_box(Vector3d(x0 + 95, 7.2, 0), Vector3d(4.3, 1.8, 1.45), -0.03, t.warm_car);
  for (double x = 0; x < 140; x += 20) {
    w.cylinders.push_back({Eigen::Vector2d(x0 + x, 8.6), 0.1, 0, 6, t.metal});
    w.cylinders.push_back({Eigen::Vector2d(x0 + x + 10, -8.6), 0.1, 0, 6, t.metal});
  }
  w.add_box(Vector3d(x0 + 45, 9.2, 0), Vector3d(0.7, 0.7, 1.1), 0.2, t.bin);
}

// The street's motion: driven fast, weaving a little.
void street_motion(Preset& p, uint64_t seed) {
  p.trajectory.start_m = Vector3d(0, 0, 1.8);
  p.trajectory.speed_mean_m_s = 6;
  p.trajectory.speed_amplitude_m_s = 4;  // 2..10 m/s
  p.trajectory.speed_period_s = 5;
  p.trajectory.weave_amplitude_m = 0.6;
  p.trajectory.weave_wavelength_m = 35;
  p.trajectory.bob_amplitude_m = 0.02;
  p.trajectory.bob_wavelength_m = 6;
  p.trajectory.yaw_amplitude_rad = 0.05;
  p.trajectory.yaw_period_s = 2.5;
  p.trajectory.pitch_amplitude_rad = 0.015;
  p.trajectory.roll_amplitude_rad = 0.015;
  Rng rig(seed, Stream::kRig);
  p.T_imu_cam = camera_mount(75 * kDeg, 8 * kDeg, Vector3d(0.2, 0.3, 0.15), rig);
  p.T_imu_lidar = lidar_mount(Vector3d(0.0, 0.0, 0.25), rig);
  p.lidar.range_max_m = 80;
}

// `blocks` of the street's 160 m block one after another on one ground, driven fast.
Preset street_of_blocks(const std::string& name, const std::string& description, int blocks, uint64_t seed,
                        Appearance appearance) {
  Preset p;
  p.name = name;
  p.description = description;
  World& w = p.world;
  w.sky_raw = 3010;
  const StreetTextures t = add_street_textures(w, seed);
  add_ground(w, -30, -25, 160.0 * blocks, 25, t.asphalt);
  for (int k = 0; k < blocks; ++k) add_street_block(w, 160.0 * k, t, appearance);
  street_motion(p, seed);
  p.frames = 80;
  p.map_voxel_m = 0.15;
  return p;
}

Preset street(uint64_t seed, Appearance appearance) {
  Preset p = street_of_blocks(
      "street", "a street between two facades with parked cars and posts, driven fast", 1, seed, appearance);
  p.max_frames = 220;  // 140 m of street
  return p;
}

// The street's block repeated ten times, about 1.6 km (issue 49's long scene: training in blocks). The
// blocks are alike: the front end would find the same facades again, the training does not mind.
Preset long_street(uint64_t seed, Appearance appearance) {
  Preset p = street_of_blocks(
      "long-street", "the street, ten 160 m blocks long, driven fast (a scene for training in blocks)", 10,
      seed, appearance);
  p.max_frames = 2300;  // 1.4 km at 6 m/s on average, short of the street's end
  // An odometry's drift over a long drive: 0.5 % of the distance and 0.6 degrees of heading per km (the
  // short presets' 0.3 mrad/m would turn 20 degrees over the street).
  p.estimator.drift_m_per_m = 0.005;
  p.estimator.drift_rad_per_m = 0.00001;
  return p;
}

Preset corridor(uint64_t seed, Appearance appearance) {
  Preset p;
  p.name = "corridor";
  p.description =
      "an indoor corridor: walls, floor, ceiling lights, doors, a lift, radiators; Livox-like LiDAR";
  World& w = p.world;
  w.sky_raw = 4050;  // never seen: the corridor is closed
  const int wall = w.add_texture(uniform(3520, 2, 3, seed + 1));
  const int floor = w.add_texture(cells(ThermalPattern::kPanel, 3505, 0.6, 0.6, 0.006, -5, 3, seed + 2));
  const int ceiling = w.add_texture(cells(ThermalPattern::kPanel, 3545, 0.6, 0.6, 0.01, -8, 2, seed + 3));
  const int door = w.add_texture(cells(ThermalPattern::kPanel, 3560, 0.45, 0.95, 0.015, -10, 4, seed + 4));
  const int lift = w.add_texture(cells(ThermalPattern::kPanel, 3470, 0.9, 2.1, 0.02, -20, 3, seed + 5));
  const int lamp = w.add_texture(uniform(4100, 20, 0.3, seed + 6));
  const int radiator =
      w.add_texture(cells(ThermalPattern::kPanel, 4250, 0.05, 0.6, 0.01, -120, 10, seed + 7));
  const int pipe = w.add_texture(uniform(3900, 5, 0.5, seed + 8));

  const double x0 = -4, x1 = 40, half = 1.6, h = 2.8;
  add_ground(w, x0, -half, x1, half, floor);
  w.add_rect({Vector3d(x0, -half, h), Vector3d::UnitX(), Vector3d::UnitY(), x1 - x0, 2 * half, {}, ceiling});
  std::vector<World::Opening> left, right;
  for (double x = 2; x + 2 < x1 - x0; x += 5) {
    left.push_back({{x, 0, x + 1.0, 2.1}, 0.1, door});
    right.push_back({{x + 2.5, 0, x + 3.5, 2.1}, 0.1, door});
  }
  add_wall_with_openings(w, Vector3d(x0, half, 0), x1 - x0, h, wall, left, appearance);
  add_wall_with_openings(w, Vector3d(x0, -half, 0), x1 - x0, h, wall, right, appearance);
  w.add_rect({Vector3d(x0, -half, 0), Vector3d::UnitY(), Vector3d::UnitZ(), 2 * half, h, {}, wall});
  w.add_rect({Vector3d(x1, -half, 0), Vector3d::UnitY(), Vector3d::UnitZ(), 2 * half, h, {}, wall});
  w.add_box(Vector3d(22, half - 0.25, 0), Vector3d(2.2, 0.5, 2.5), 0, lift);  // the lift shaft's front
  for (double x = 0; x < x1 - 1; x += 4)
    w.add_rect({Vector3d(x, -0.3, h - 0.01), Vector3d::UnitX(), Vector3d::UnitY(), 1.2, 0.6, {}, lamp});
  for (double x = 6; x < x1 - 2; x += 10)
    w.add_box(Vector3d(x, -half + 0.06, 0.15), Vector3d(1.0, 0.1, 0.6), 0, radiator);
  w.cylinders.push_back({Eigen::Vector2d(x1 - 0.15, half - 0.15), 0.05, 0, h, pipe});
  w.cylinders.push_back({Eigen::Vector2d(15, -half + 0.08), 0.04, 0, h, pipe});

  p.trajectory.start_m = Vector3d(0, 0, 1.4);
  p.trajectory.speed_mean_m_s = 1.0;
  p.trajectory.speed_amplitude_m_s = 0.5;
  p.trajectory.speed_period_s = 5;
  p.trajectory.weave_amplitude_m = 0.2;
  p.trajectory.weave_wavelength_m = 6;
  p.trajectory.yaw_amplitude_rad = 0.12;
  p.trajectory.pitch_amplitude_rad = 0.05;
  Rng rig(seed, Stream::kRig);
  p.T_imu_cam = camera_mount(0, -5 * kDeg, Vector3d(0.1, 0.0, 0.08), rig);
  p.T_imu_lidar = lidar_mount(Vector3d(0.05, 0.0, 0.12), rig);
  p.lidar.pattern = LidarPattern::kRosette;
  p.lidar.range_noise_m = 0.02;
  p.lidar.range_min_m = 0.3;
  p.estimator.anchor_min_gradient_raw = 3;  // indoor contrast is weak
  p.frames = 60;
  p.max_frames = 350;  // stops short of the end wall 40 m ahead
  p.map_voxel_m = 0.05;
  return p;
}

}  // namespace

std::string NucOptions::check() const {
  if (first_min < 1 || first_max < first_min) return "first_min/first_max: need 1 <= min <= max";
  if (interval_min < 2 || interval_max < interval_min)
    return "interval_min/interval_max: need 2 <= min <= max";
  if (length_max < 1 || length_max >= interval_min) return "length_max: need 1 <= length_max < interval_min";
  return "";
}

std::vector<std::string> preset_names() {
  return {"facade", "street", "corridor", "long-street"};
}

Appearance parse_appearance(const std::string& name) {
  if (name == "textured") return Appearance::kTextured;
  if (name == "flat") return Appearance::kFlat;
  throw std::invalid_argument("unknown appearance '" + name + "' (known: textured, flat)");
}

std::string appearance_name(Appearance appearance) {
  return appearance == Appearance::kFlat ? "flat" : "textured";
}

Preset make_preset(const std::string& name, uint64_t seed, Appearance appearance) {
  for (auto* make : {&facade, &street, &corridor, &long_street}) {
    Preset p = make(seed, appearance);
    if (p.name != name) continue;
    if (appearance == Appearance::kTextured) weather(p);
    p.world.build_index();
    return p;
  }
  std::string names;
  for (const auto& n : preset_names()) names += (names.empty() ? "" : ", ") + n;
  throw std::invalid_argument("unknown preset '" + name + "' (known: " + names + ")");
}

}  // namespace litgs::host::synth
