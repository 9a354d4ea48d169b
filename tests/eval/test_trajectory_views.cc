// The report's trajectory views (host/eval/trajectory_eval.h): the side view shows the height error the top
// view hides, for refined poses against their priors without ground truth.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>

#include "host/eval/trajectory_eval.h"
#include "io/scene.h"
#include "io/tum.h"

namespace litgs::host {
namespace {
namespace fs = std::filesystem;

TEST(TrajectoryViews, TheSideViewShowsAHeightErrorTheTopViewHides) {
  const fs::path dir = fs::temp_directory_path() / ("litgs-trajectory-views-" + std::to_string(::getpid()));
  fs::remove_all(dir);
  io::Scene scene;
  scene.config.camera.width = scene.config.camera.height = 16;
  scene.config.camera.fx = scene.config.camera.fy = 10;
  scene.config.camera.cx = scene.config.camera.cy = 7.5;
  scene.config.camera.bit_depth = 8;
  scene.config.has_lidar_map = false;
  std::vector<io::TumPose> prior;
  for (int i = 0; i < 10; ++i) {  // 9 m along x, zigzag 0.5 m in y, flat in z
    io::TumPose p;
    p.t_s = 100 + i;
    p.p_world = {1.0 * i, 0.5 * (i % 2), 0};
    prior.push_back(p);
    scene.frames.push_back({p.t_s, {}});
    p.p_world.z() += i >= 5 ? 0.2 : 0.0;  // refinement lifts the second half by 20 cm
    scene.poses.push_back(p);
  }
  io::Image blank;
  blank.width = blank.height = 16;
  blank.bit_depth = 8;
  blank.data.assign(256, 0);
  io::write_scene(
      dir, scene, [&](size_t) { return blank; }, [](size_t) { return io::PointCloud{}; });
  io::write_tum(dir / "poses_prior.txt", prior);

  std::string why;
  const auto t = evaluate_trajectories(dir, &why);
  ASSERT_TRUE(t) << why;
  ASSERT_EQ(t->prior_side.size(), 10u);
  ASSERT_EQ(t->estimate_top.size(), 10u);
  for (size_t i = 0; i < 10; ++i) {
    const double top = (t->estimate_top[i] - t->prior_top[i]).norm();
    const double side = t->estimate_side[i].y() - t->prior_side[i].y();  // up is up
    EXPECT_LT(top, 1e-9) << "frame " << i;                               // seen from above, nothing moved
    EXPECT_NEAR(side, i >= 5 ? 0.2 : 0.0, 1e-9) << "frame " << i;
  }
  const nlohmann::json j = to_json(*t);
  EXPECT_EQ(j["side_view"]["estimate"].size(), 10u);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace litgs::host
