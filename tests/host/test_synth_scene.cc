// The generated scene as a whole: byte-for-byte determinism, and its ground truth read back through the io
// reader and checked against itself (planes, projections, drift, IMU, frozen frames); bad arguments.
#include <gtest/gtest.h>
#include <unistd.h>

#include <Eigen/Cholesky>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <fstream>
#include <map>
#include <sstream>

#include "host/synth/presets.h"
#include "host/synth/synth.h"
#include "io/image.h"
#include "io/pcd.h"
#include "io/scene.h"
#include "io/scene_text.h"

namespace litgs::host::synth {
namespace {
namespace fs = std::filesystem;

class SynthSceneTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::temp_directory_path() /
           (std::string("litgs-synth-") + info->name() + "-" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  // A small facade scene: enough frames for a NUC freeze, small images for speed.
  SynthOptions small(const std::string& sub, const std::string& preset = "facade") const {
    SynthOptions o;
    o.preset = preset;
    o.seed = 42;
    o.frames = 24;
    o.width = 160;
    o.height = 128;
    o.out = dir_ / sub;
    return o;
  }

  fs::path dir_;
};

std::string bytes(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

std::map<std::string, std::string> all_files(const fs::path& dir) {
  std::map<std::string, std::string> files;
  for (const auto& e : fs::recursive_directory_iterator(dir))
    if (e.is_regular_file()) files[fs::relative(e.path(), dir).string()] = bytes(e.path());
  return files;
}

Eigen::Isometry3d to_iso(const io::TumPose& p) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = p.q_world_body.toRotationMatrix();
  T.translation() = p.p_world;
  return T;
}

TEST_F(SynthSceneTest, SameSeedSameBytesOtherSeedOtherBytes) {
  SynthOptions a = small("a"), b = small("b"), c = small("c");
  a.threads = 1;  // threads must not change a byte
  b.threads = 3;
  c.seed = 43;
  generate_synthetic_scene(a);
  generate_synthetic_scene(b);
  generate_synthetic_scene(c);
  const auto fa = all_files(a.out), fb = all_files(b.out), fc = all_files(c.out);
  ASSERT_GT(fa.size(), 24u * 3);  // thermal, thermal8, scans, and the rest
  ASSERT_EQ(fa.size(), fb.size());
  for (const auto& [name, content] : fa) {
    ASSERT_TRUE(fb.count(name)) << name;
    EXPECT_TRUE(content == fb.at(name)) << name << " differs between two runs with the same seed";
  }
  EXPECT_NE(fa.at("poses.txt"), fc.at("poses.txt"));
  EXPECT_NE(fa.at("lidar/map.pcd"), fc.at("lidar/map.pcd"));
}

TEST_F(SynthSceneTest, GroundTruthHoldsWhenReadBack) {
  const SynthOptions o = small("s");
  const SynthReport report = generate_synthetic_scene(o);
  const Preset preset = make_preset(o.preset, o.seed);
  const io::Scene s = io::read_scene(o.out);

  // Counts.
  ASSERT_EQ(s.frames.size(), 24u);
  ASSERT_EQ(s.poses.size(), 24u);
  ASSERT_TRUE(s.gt && s.gt->map && s.map);
  ASSERT_EQ(s.gt->poses.size(), 24u);
  EXPECT_EQ(s.scans.size(), 24u);
  EXPECT_EQ(s.config.camera.width, 160);
  EXPECT_EQ(s.config.camera.bit_depth, 16);
  EXPECT_EQ(s.map->size(), s.gt->map->size());
  EXPECT_EQ(s.map->size(), report.map_points);
  EXPECT_GT(s.map->size(), 10000u);
  EXPECT_GT(s.anchors.size(), 100u);
  EXPECT_EQ(s.gt->planes.size(), preset.world.rects.size());

  // LiDAR map points lie on their true plane within the range noise (the error is along the beam, so its
  // normal component is at most the range error); the noise-free map lies on it exactly.
  const io::ScalarField* plane_id = s.gt->map->field("plane_id");
  ASSERT_NE(plane_id, nullptr);
  const double sigma = preset.lidar.range_noise_m;
  double sum2 = 0;
  size_t on_planes = 0, outliers = 0;
  for (size_t i = 0; i < s.map->size(); ++i) {
    const int id = static_cast<int>(plane_id->values[i]);
    if (id < 0) continue;
    ASSERT_LT(id, static_cast<int>(s.gt->planes.size()));
    const io::Plane& pl = s.gt->planes[id];
    EXPECT_NEAR(pl.n.dot(s.gt->map->positions[i]) + pl.d, 0, 1e-9);
    const double r = pl.n.dot(s.map->positions[i]) + pl.d;
    sum2 += r * r;
    outliers += std::abs(r) > 5 * sigma ? 1 : 0;
    ++on_planes;
  }
  ASSERT_GT(on_planes, s.map->size() * 9 / 10);
  EXPECT_LT(std::sqrt(sum2 / static_cast<double>(on_planes)), sigma);
  EXPECT_GT(std::sqrt(sum2 / static_cast<double>(on_planes)), sigma / 5);  // there is noise
  EXPECT_EQ(outliers, 0u);

  // Scans are in the LiDAR frame: through the true camera pose and T_cam_lidar they land on the true planes
  // (a wrong or inverted extrinsic would put them centimetres to metres off).
  for (const size_t f : {size_t{0}, size_t{17}}) {
    const io::PointCloud scan = io::read_pcd(o.out / s.scans[f].file);
    ASSERT_GT(scan.size(), 1000u);
    ASSERT_EQ(s.scans[f].t_s, s.gt->poses[f].t_s);
    const Eigen::Matrix4d T_world_lidar = to_iso(s.gt->poses[f]).matrix() * s.config.T_cam_lidar;
    size_t off = 0;
    for (const Eigen::Vector3d& p : scan.positions) {
      const Eigen::Vector3d w = (T_world_lidar * p.homogeneous()).head<3>();
      double nearest = 1e9;
      for (const io::Plane& pl : s.gt->planes) nearest = std::min(nearest, std::abs(pl.n.dot(w) + pl.d));
      off += nearest > 5 * sigma ? 1 : 0;
    }
    EXPECT_LT(off, scan.size() / 50) << "scan " << f;  // the few returns off planes hit the posts
  }

  // Anchors: each projects into the image with some true pose; their errors against gt/anchors.txt are
  // consistent with their covariances (mean squared Mahalanobis distance ~ 3).
  const io::CameraIntrinsics& K = s.config.camera;
  const auto true_anchors = io::read_anchors(o.out / "gt/anchors.txt");
  ASSERT_EQ(true_anchors.size(), s.anchors.size());
  double chi2 = 0;
  for (size_t a = 0; a < s.anchors.size(); ++a) {
    bool inside = false;
    for (const auto& pose : s.gt->poses) {
      const Eigen::Vector3d pc = to_iso(pose).inverse() * s.anchors[a].p_world;
      if (pc.z() <= 0.1) continue;
      const double u = K.fx * pc.x() / pc.z() + K.cx, v = K.fy * pc.y() / pc.z() + K.cy;
      inside = inside || (u >= 0 && u <= K.width - 1 && v >= 0 && v <= K.height - 1);
    }
    EXPECT_TRUE(inside) << "anchor " << a << " is seen by no camera";
    const Eigen::Vector3d e = s.anchors[a].p_world - true_anchors[a].p_world;
    chi2 += e.dot(s.anchors[a].cov_m2.ldlt().solve(e));
  }
  EXPECT_NEAR(chi2 / static_cast<double>(s.anchors.size()), 3.0, 0.6);

  // Estimated poses drift from the true ones by the intended rates: the rotation drift R_d = R_est R_true^T
  // (a rotation about the first position) and the translation left after undoing it both grow linearly
  // with the distance travelled; least-squares slopes over all frames average the per-frame jitter away.
  const Trajectory traj(preset.trajectory);
  Eigen::Vector3d rot_num = Eigen::Vector3d::Zero(), trans_num = Eigen::Vector3d::Zero();
  double den = 0, travelled = 0;
  const Eigen::Vector3d pivot = s.gt->poses.front().p_world;
  for (size_t i = 0; i < s.poses.size(); ++i) {
    const double dist =
        traj.at(0.5 + static_cast<double>(i) / preset.frame_rate_hz).distance_m - traj.at(0.5).distance_m;
    const Eigen::Quaterniond q_d = s.poses[i].q_world_body * s.gt->poses[i].q_world_body.conjugate();
    const Eigen::AngleAxisd aa(q_d);
    const Eigen::Vector3d c = s.poses[i].p_world - pivot - q_d * (s.gt->poses[i].p_world - pivot);
    rot_num += dist * aa.angle() * aa.axis();
    trans_num += dist * c;
    den += dist * dist;
    travelled = dist;
  }
  ASSERT_GT(travelled, 1.0);
  EXPECT_NEAR((trans_num / den).norm(), preset.estimator.drift_m_per_m,
              0.15 * preset.estimator.drift_m_per_m);
  EXPECT_NEAR((rot_num / den).norm(), preset.estimator.drift_rad_per_m,
              0.35 * preset.estimator.drift_rad_per_m);
  const double first = (s.poses.front().p_world - s.gt->poses.front().p_world).norm();
  EXPECT_LT(first, 4 * preset.estimator.pose_noise_m * std::sqrt(3.0));

  // The IMU's integrated rotation over a short window matches the true rotation (camera to IMU through
  // the extrinsics); the window turns enough that a broken gyro would fail.
  const Eigen::Matrix4d T_cam_imu = s.config.T_cam_lidar * s.config.T_imu_lidar.inverse();
  const Eigen::Matrix3d R_cam_imu = T_cam_imu.topLeftCorner<3, 3>();
  const size_t f0 = 4, f1 = 14;  // one second
  const Eigen::Matrix3d R0 = s.gt->poses[f0].q_world_body.toRotationMatrix() * R_cam_imu;
  const Eigen::Matrix3d R1 = s.gt->poses[f1].q_world_body.toRotationMatrix() * R_cam_imu;
  Eigen::Matrix3d R = R0;
  for (size_t k = 0; k + 1 < s.imu.size(); ++k) {
    const double ta = std::max(s.imu[k].t_s, s.gt->poses[f0].t_s);
    const double tb = std::min(s.imu[k + 1].t_s, s.gt->poses[f1].t_s);
    if (tb <= ta) continue;
    const Eigen::Vector3d w = 0.5 * (s.imu[k].gyro_rad_s + s.imu[k + 1].gyro_rad_s) * (tb - ta);
    if (w.norm() > 0) R = R * Eigen::AngleAxisd(w.norm(), w.normalized()).toRotationMatrix();
  }
  const double true_turn = Eigen::AngleAxisd(R0.transpose() * R1).angle();
  const double err = Eigen::AngleAxisd(R.transpose() * R1).angle();
  EXPECT_GT(true_turn, 0.05);
  EXPECT_LT(err, 0.01) << "true turn " << true_turn;

  // Frozen frames: exact repeats of the previous frame, listed in gt/frozen.txt; other frames differ.
  std::ifstream frozen_file(o.out / "gt/frozen.txt");
  std::vector<size_t> frozen;
  for (std::string line; std::getline(frozen_file, line);)
    if (!line.empty() && line[0] != '#') frozen.push_back(std::stoul(line.substr(line.find(' ') + 1)));
  ASSERT_FALSE(frozen.empty());
  EXPECT_EQ(static_cast<int>(frozen.size()), report.frozen_frames);
  for (size_t i = 1; i < s.frames.size(); ++i) {
    const bool is_frozen = std::find(frozen.begin(), frozen.end(), i) != frozen.end();
    const io::Image prev = io::load_frame(o.out, s, i - 1), cur = io::load_frame(o.out, s, i);
    EXPECT_EQ(prev.data == cur.data, is_frozen) << "frame " << i;
    const auto name = s.frames[i].image.filename();
    const io::Image a8 = io::read_image(o.out / "thermal8" / name);
    EXPECT_EQ(a8.bit_depth, 8);
    EXPECT_EQ(a8.width, 160);
    if (is_frozen) {
      EXPECT_EQ(a8.data, io::read_image(o.out / "thermal8" / s.frames[i - 1].image.filename()).data);
    }
  }

  // Raw values in a physically plausible range, with texture.
  const io::Image img = io::load_frame(o.out, s, 0);
  const auto [lo, hi] = std::minmax_element(img.data.begin(), img.data.end());
  EXPECT_GT(*lo, 2500);
  EXPECT_LT(*hi, 5000);
  EXPECT_GT(*hi - *lo, 100);
}

TEST_F(SynthSceneTest, EveryPresetGenerates) {
  for (const std::string& name : preset_names()) {
    SynthOptions o = small(name, name);
    o.frames = 3;
    o.width = 64;
    o.height = 48;
    const SynthReport r = generate_synthetic_scene(o);
    const io::Scene s = io::read_scene(o.out);
    EXPECT_EQ(s.frames.size(), 3u) << name;
    EXPECT_GT(r.map_points, 1000u) << name;
    EXPECT_FALSE(s.anchors.empty()) << name;
  }
}

template <class F>
void expect_invalid(F&& f, const std::string& part) {
  try {
    f();
    ADD_FAILURE() << "expected std::invalid_argument mentioning '" << part << "'";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find(part), std::string::npos) << e.what();
  }
}

// --frame-rate samples the same path more densely: frame 2 at 20 Hz is frame 1 at 10 Hz, and the presets'
// frame limits scale with the rate.
TEST_F(SynthSceneTest, AHigherFrameRateSamplesTheSamePathMoreDensely) {
  SynthOptions slow = small("slow");
  slow.frames = 2;
  slow.width = slow.height = 32;
  SynthOptions fast = slow;
  fast.out = dir_ / "fast";
  fast.frames = 3;
  fast.frame_rate_hz = 20;
  generate_synthetic_scene(slow);
  generate_synthetic_scene(fast);
  const io::Scene a = io::read_scene(slow.out), b = io::read_scene(fast.out);
  ASSERT_EQ(a.gt->poses.size(), 2u);
  ASSERT_EQ(b.gt->poses.size(), 3u);
  EXPECT_DOUBLE_EQ(b.gt->poses[2].t_s, a.gt->poses[1].t_s);
  EXPECT_LT((b.gt->poses[2].p_world - a.gt->poses[1].p_world).norm(), 1e-12);
  EXPECT_GT((b.gt->poses[1].p_world - a.gt->poses[1].p_world).norm(), 1e-3) << "frame 1 at 20 Hz is between";

  SynthOptions too_many = small("too-many");
  too_many.frame_rate_hz = 30;
  too_many.frames = 1200;
  expect_invalid([&] { generate_synthetic_scene(too_many); }, "covers at most 1140 frames at 30 Hz");
  too_many.frame_rate_hz = 0;
  expect_invalid([&] { generate_synthetic_scene(too_many); }, "frame_rate_hz");
  EXPECT_FALSE(fs::exists(too_many.out));
}

TEST_F(SynthSceneTest, BadArgumentsAreClearErrors) {
  SynthOptions o = small("bad");
  o.preset = "moon";
  expect_invalid([&] { generate_synthetic_scene(o); }, "unknown preset 'moon'");
  o = small("bad");
  o.frames = 0;
  expect_invalid([&] { generate_synthetic_scene(o); }, "frames");
  o = small("bad");
  o.frames = 5000;
  expect_invalid([&] { generate_synthetic_scene(o); }, "covers at most 380 frames");
  o = small("bad");
  o.width = 0;
  expect_invalid([&] { generate_synthetic_scene(o); }, "width");
  o = small("bad");
  o.height.reset();
  expect_invalid([&] { generate_synthetic_scene(o); }, "width/height");
  o = small("bad");
  o.out.clear();
  expect_invalid([&] { generate_synthetic_scene(o); }, "out");
  EXPECT_FALSE(fs::exists(dir_ / "bad")) << "nothing is written for bad arguments";

  // A non-empty --out: refused without --force (and untouched), replaced with it (other files kept).
  o = small("busy");
  o.frames = 2;
  o.width = 32;
  o.height = 32;
  fs::create_directories(o.out / "thermal");
  std::ofstream(o.out / "notes.txt") << "mine";
  std::ofstream(o.out / "thermal/1.png") << "stale";
  expect_invalid([&] { generate_synthetic_scene(o); }, "not empty");
  EXPECT_FALSE(fs::exists(o.out / "scene.yaml"));
  o.force = true;
  generate_synthetic_scene(o);
  EXPECT_EQ(io::read_scene(o.out).frames.size(), 2u);
  EXPECT_EQ(bytes(o.out / "notes.txt"), "mine");
}

}  // namespace
}  // namespace litgs::host::synth
