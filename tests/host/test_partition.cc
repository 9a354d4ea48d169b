// Block partitioning (host/partition): the plan's geometry, the named bad inputs, and partition + merge on a
// small synthetic scene.
#include <gtest/gtest.h>
#include <unistd.h>

#include <fstream>
#include <random>

#include "host/partition/block_plan.h"
#include "host/partition/partition_scene.h"
#include "host/partition/seam_metrics.h"
#include "host/synth/synth.h"
#include "host/train/training_data.h"
#include "io/gaussian_ply.h"
#include "io/scene.h"

namespace litgs::host::partition {
namespace {
namespace fs = std::filesystem;

// A camera at `centre` looking along +y (x right, z down in the camera: the world's z is up).
PlanView view_at(const Eigen::Vector3d& centre) {
  PlanView v;
  v.T_world_cam.linear() << 1, 0, 0, 0, 0, 1, 0, -1, 0;
  v.T_world_cam.translation() = centre;
  v.fx = v.fy = 100;
  v.cx = 80, v.cy = 60, v.width = 160, v.height = 120;
  return v;
}

// Cameras along x at y = 0, a wall of map points at y = 5 from x = x0 to x1.
std::vector<PlanView> street_views(size_t n, double length) {
  std::vector<PlanView> views;
  for (size_t i = 0; i < n; ++i)
    views.push_back(view_at({length * static_cast<double>(i) / static_cast<double>(n - 1), 0, 1.5}));
  return views;
}
std::vector<Eigen::Vector3d> wall(double x0, double x1) {
  std::vector<Eigen::Vector3d> map;
  for (double x = x0; x < x1; x += 0.1)
    for (double z = 0; z < 3; z += 0.25) map.emplace_back(x, 5, z);
  return map;
}

TEST(PartitionPlan, CoreCellsTileThePlaneAndSplitTheCamerasEvenly) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-50, 50);
  std::vector<PlanView> views;
  for (int i = 0; i < 600; ++i) views.push_back(view_at({u(rng), 0.3 * u(rng), 1.5}));
  PartitionOptions o;
  o.columns = 3;
  o.rows = 2;
  o.overlap_m = 2;
  const BlockPlan plan = plan_blocks(views, wall(-60, 60), o);
  ASSERT_EQ(plan.blocks.size(), 6u);
  for (int i = 0; i < 20000; ++i) {
    const double x = 3 * u(rng), y = 3 * u(rng);
    int homes = 0;
    for (const Block& b : plan.blocks) homes += b.core.contains(x, y);
    ASSERT_EQ(homes, 1) << x << " " << y;
  }
  for (const Block& b : plan.blocks) {
    size_t in_core = 0;
    for (const auto& v : views)
      in_core += b.core.contains(v.T_world_cam.translation().x(), v.T_world_cam.translation().y());
    EXPECT_NEAR(static_cast<double>(in_core), 100.0, 1.0) << b.name;
    EXPECT_GE(b.views_by_position, in_core) << b.name;  // the overlap adds the neighbours' border cameras
    EXPECT_EQ(b.expanded.x0, b.core.x0 - 2);
    EXPECT_EQ(b.expanded.y1, b.core.y1 + 2);
  }
}

TEST(PartitionPlan, AutoTakesTheBlockCountFromTheBudgetAndLaysItAlongTheStreet) {
  PartitionOptions o;
  o.max_gaussians_per_block = 300000;
  o.scene_gaussians = 1000000;
  const BlockPlan plan = plan_blocks(street_views(200, 400), wall(0, 400), o);
  EXPECT_EQ(plan.columns, 4u);  // ceil(1M / 300k) along x, the street's direction
  EXPECT_EQ(plan.rows, 1u);
  EXPECT_EQ(blocks_needed(1000000, 300000), 4u);
  EXPECT_EQ(blocks_needed(10, 300000), 1u);
  // A degree-3 thermal model: 16 floats per Gaussian in its largest buffer; 128 MiB holds 2,097,152.
  EXPECT_EQ(gaussians_per_buffer(128ull << 20, 3, 1), 2097152u);
}

TEST(PartitionPlan, AViewOutsideTheBoundsJoinsTheBlockItLooksInto) {
  // Cameras along x in [0, 20], a wall in front of them; one more camera beyond the wall's end at x = 30
  // turned to look back along -x at the first block's part of the wall.
  std::vector<PlanView> views = street_views(21, 20);
  PlanView back = view_at({30, 5, 1.5});
  back.T_world_cam.linear() << 0, 0, -1, 1, 0, 0, 0, -1, 0;  // optical axis along -x, z up stays up
  views.push_back(back);
  std::vector<Eigen::Vector3d> map = wall(0, 20);
  PartitionOptions o;
  o.columns = 2;
  o.rows = 1;
  o.overlap_m = 1;
  const BlockPlan plan = plan_blocks(views, map, o);
  const Block& first = plan.blocks[0];
  auto has_back = [](const Block& b) {
    return std::find(b.views.begin(), b.views.end(), 21u) != b.views.end();
  };
  ASSERT_FALSE(first.expanded.contains(30, 5));
  EXPECT_TRUE(has_back(plan.blocks[1])) << "inside the second block's bounds";
  // About half of the wall it sees lies in the first block's core (x < 10.5).
  EXPECT_TRUE(has_back(first)) << "the camera looking back sees the first block's wall";
  EXPECT_GE(first.views_by_visibility, 1u);
  o.visibility_share = 0.6;
  EXPECT_FALSE(has_back(plan_blocks(views, map, o).blocks[0])) << "under the share asked for";
}

TEST(PartitionBadInput, BlockWithNoViews) {
  // Two cameras at one place, asked for three rows: two cells hold no camera and nothing grows into them.
  const std::vector<PlanView> views{view_at({0, 0, 1.5}), view_at({0, 0, 1.5})};
  PartitionOptions o;
  o.columns = 1;
  o.rows = 3;
  o.overlap_m = 0;
  const BlockPlan plan = plan_blocks(views, wall(-5, 5), o);
  try {
    check_blocks(plan, views.size());
    FAIL() << "a block without views was accepted";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("block-0-0 has no views"), std::string::npos) << e.what();
  }
}

TEST(PartitionBadInput, BlockWhoseViewsSeeNothingOfItsCell) {
  // The map holds only the wall's first half: the second block's cameras see none of their own cell.
  const std::vector<PlanView> views = street_views(40, 20);
  PartitionOptions o;
  o.columns = 2;
  o.rows = 1;
  o.overlap_m = 0.5;
  const BlockPlan plan = plan_blocks(views, wall(0, 8), o);
  try {
    check_blocks(plan, views.size());
    FAIL() << "a block whose views see nothing of its cell was accepted";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("no view of block-1-0 sees its core cell"), std::string::npos)
        << e.what();
  }
}

TEST(PartitionBadInput, NonFinitePoseOrNoViews) {
  std::vector<PlanView> views = street_views(5, 4);
  PartitionOptions o;
  o.columns = o.rows = 1;
  EXPECT_THROW(plan_blocks({}, wall(0, 4), o), std::invalid_argument);
  views[2].T_world_cam.translation().x() = std::nan("");
  EXPECT_THROW(plan_blocks(views, wall(0, 4), o), std::invalid_argument);
  o.rows = 0;  // columns without rows
  EXPECT_THROW(o.check(), std::invalid_argument);
}

// Two blocks split at x = 0, one view looking down the world's +z at a surface 5 m away: the render errs by
// 0.01 in block 0 and by 0.1 in block 1, so their PSNRs are 40 and 20 dB; the seam band of 0.5 m is the
// columns whose surface point lies within 0.5 m of x = 0.
TEST(PartitionSeams, PsnrPerBlockAndAlongTheSeam) {
  const fs::path dir = fs::temp_directory_path() / ("litgs-seams-" + std::to_string(::getpid()));
  fs::create_directories(dir);
  std::ofstream(dir / kPartitionFile)
      << R"({"overlap_m": 1.0, "blocks": [{"name": "block-0-0", "core": [null, 0.0, null, null]},
                                          {"name": "block-1-0", "core": [0.0, null, null, null]}]})";
  kernels::SplatCamera cam;  // identity pose: camera frame = world frame
  cam.fx = cam.fy = 100;
  cam.cx = 80, cam.cy = 60, cam.width = 160, cam.height = 120;
  ViewImages v;
  v.name = "v";
  v.width = 160, v.height = 120;
  const size_t n = 160 * 120;
  v.target.assign(n, 0.5f);
  v.depth_m.assign(n, 5.0f);
  v.alpha.assign(n, 1.0f);
  v.render.resize(n);
  for (size_t p = 0; p < n; ++p) v.render[p] = p % 160 < 80 ? 0.51f : 0.6f;  // x < 0: block 0
  v.alpha[0] = 0.1f;                                                         // one pixel without a surface
  const SeamMetrics m = seam_metrics(dir, {v}, {cam});
  fs::remove_all(dir);
  EXPECT_EQ(m.seam_width_m, 0.5);  // half the overlap
  ASSERT_EQ(m.blocks.size(), 2u);
  EXPECT_NEAR(m.blocks[0].psnr_db, 40.0, 1e-4);  // float32 0.51 - 0.5
  EXPECT_NEAR(m.blocks[1].psnr_db, 20.0, 1e-4);
  EXPECT_EQ(m.unplaced, 1u);
  EXPECT_EQ(m.blocks[0].pixels + m.blocks[1].pixels, n - 1);
  // |x| = |u + 0.5 - 80| / 100 * 5 < 0.5: columns 70..89, 20 of them, in every row.
  EXPECT_EQ(m.seams.pixels, 20u * 120u);
  EXPECT_EQ(m.interior.pixels, n - 1 - 20u * 120u);
  EXPECT_THROW(seam_metrics(dir, {v}, {}), std::invalid_argument);
}

class PartitionSceneTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::temp_directory_path() /
           (std::string("litgs-partition-") + info->name() + "-" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  fs::path synth(const std::string& name, uint64_t seed) const {
    synth::SynthOptions o;
    o.preset = "street";
    o.seed = seed;
    o.frames = 24;
    o.width = 96;
    o.height = 64;
    o.out = dir_ / name;
    synth::generate_synthetic_scene(o);
    return o.out;
  }
  fs::path dir_;
};

TEST_F(PartitionSceneTest, BlocksAreScenesAndMergeKeepsEachGaussianOnce) {
  const fs::path scene = synth("street", 1);
  PartitionOptions o;
  o.columns = 3;
  o.rows = 1;
  const PartitionReport r = partition_scene(scene, dir_ / "part", o);
  ASSERT_EQ(r.plan.blocks.size(), 3u);
  // Each block reads back as a scene with its own frames and its part of the map, and none of the scene's
  // held-out frames (0, 8, 16): eval of the merged model scores views no block trained on.
  const io::Scene whole = io::read_scene(scene);
  EXPECT_EQ(r.heldout_frames, 3u);
  // One intensity window for all blocks, the whole scene's as training takes it, so their models share a
  // scale, not each its own percentiles.
  const TrainingData whole_data = load_training_data(scene, {});
  for (const Block& b : r.plan.blocks) {
    const io::Scene s = io::read_scene(dir_ / "part/blocks" / b.name);
    ASSERT_TRUE(s.config.intensity_window) << b.name;
    EXPECT_EQ(s.config.intensity_window->first, whole_data.stretch_low) << b.name;
    EXPECT_EQ(s.config.intensity_window->second, whole_data.stretch_high) << b.name;
    EXPECT_EQ(load_training_data(dir_ / "part/blocks" / b.name, {}).stretch_high, whole_data.stretch_high);
    EXPECT_EQ(s.frames.size(), b.views.size()) << b.name;
    EXPECT_EQ(s.map->size(), b.map_points.size()) << b.name;
    for (const auto& f : s.frames)
      for (size_t i = 0; i < whole.frames.size(); i += 8) EXPECT_NE(f.t_s, whole.frames[i].t_s) << b.name;
  }
  // Models standing in for trainings: Gaussians spread over each block's expanded bounds.
  std::mt19937 rng(5);
  std::vector<Eigen::Vector3d> all;
  for (const Block& b : r.plan.blocks) {
    kernels::GaussianModel m;
    m.channels = 1;
    m.sh_degree = 0;
    const io::Scene s = io::read_scene(dir_ / "part/blocks" / b.name);
    const auto& pts = s.map->positions;
    m.resize(2000);
    for (size_t i = 0; i < m.size(); ++i) {
      const Eigen::Vector3d p = pts[std::uniform_int_distribution<size_t>(0, pts.size() - 1)(rng)];
      for (int k = 0; k < 3; ++k) m.means[3 * i + k] = static_cast<float>(p[k]);
      m.quats[4 * i] = 1;
      all.push_back(p.cast<float>().cast<double>());
    }
    fs::create_directories(dir_ / "part/blocks" / b.name / kBlockTrainDir);
    io::write_gaussian_ply(dir_ / "part/blocks" / b.name / kBlockTrainDir / "point_cloud.ply", m);
  }
  const MergeReport mr = merge_blocks(dir_ / "part", dir_ / "merged.ply");
  const kernels::GaussianModel merged = io::read_gaussian_ply(dir_ / "merged.ply");
  EXPECT_EQ(merged.size(), mr.gaussians);
  size_t expected = 0;
  for (size_t k = 0; k < r.plan.blocks.size(); ++k)
    for (size_t i = 2000 * k; i < 2000 * (k + 1); ++i)
      expected += r.plan.blocks[k].core.contains(all[i].x(), all[i].y());
  EXPECT_EQ(mr.gaussians, expected);
  size_t dropped = 0;
  for (const auto& b : mr.blocks) dropped += b.gaussians - b.kept;
  EXPECT_GT(dropped, 0u) << "the overlap put some of each block's Gaussians in a neighbour's core";

  // A missing block model is named.
  fs::remove(dir_ / "part/blocks/block-1-0" / kBlockTrainDir / "point_cloud.ply");
  try {
    merge_blocks(dir_ / "part", dir_ / "merged2.ply");
    FAIL() << "merged without block-1-0's model";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("block-1-0 has no model"), std::string::npos) << e.what();
  }
  EXPECT_FALSE(fs::exists(dir_ / "merged2.ply"));
}

TEST_F(PartitionSceneTest, APartitionFolderOfAnotherSceneIsRefused) {
  const fs::path a = synth("a", 1), b = synth("b", 2);
  PartitionOptions o;
  o.columns = 2;
  o.rows = 1;
  partition_scene(a, dir_ / "part", o);
  const std::string before = [&] {
    std::ifstream in(dir_ / "part" / kPartitionFile);
    return std::string(std::istreambuf_iterator<char>(in), {});
  }();
  try {
    partition_scene(b, dir_ / "part", o);
    FAIL() << "a partition folder of another scene was reused";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("holds a partition of another scene"), std::string::npos)
        << e.what();
  }
  std::ifstream in(dir_ / "part" / kPartitionFile);
  EXPECT_EQ(std::string(std::istreambuf_iterator<char>(in), {}), before) << "the first partition was touched";
  EXPECT_NO_THROW(partition_scene(a, dir_ / "part", o)) << "the same scene cut the same way again is fine";
  o.columns = 3;
  EXPECT_THROW(partition_scene(a, dir_ / "part", o), std::runtime_error) << "cut another way: refused";
}

}  // namespace
}  // namespace litgs::host::partition
