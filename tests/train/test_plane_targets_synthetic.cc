// The geometric loss's per-pixel targets on the synthetic facade, against the surface each pixel really
// sees (a ray cast into the generator's world from the true pose). A sparse LiDAR map projected point by
// point lets points of a farther surface show through the gaps of a nearer one (the ground behind the
// transformer box, window glass behind the wall's edge); such a target pulls the rendered depth onto a
// surface the pixel does not see.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>

#include "host/synth/presets.h"
#include "host/synth/synth.h"
#include "host/train/lidar_planes.h"
#include "host/train/training_data.h"
#include "io/scene.h"

namespace litgs::host {
namespace {

namespace fs = std::filesystem;

struct TargetQuality {
  size_t valid = 0;       // pixels with a target
  size_t off = 0;         // whose target depth misses the visible surface by more than the tolerance
  double sq = 0;          // sum of the others' squared residuals along the normal (what the loss measures)
  double coverage = 0;    // valid / pixels that see a true plane
};

class FacadeTargets : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = fs::temp_directory_path() / ("litgs-plane-targets-" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    synth::SynthOptions s;
    s.out = dir_;
    s.seed = 1;
    s.frames = 24;
    synth::generate_synthetic_scene(s);
    TrainingDataOptions t;
    t.true_poses = true;
    t.holdout_every = 0;
    data_ = new TrainingData(load_training_data(dir_, t));
    const io::Scene scene = io::read_scene(dir_);
    map_ = new PlanarMap(fit_planes(scene.map->positions, PlaneFitOptions{}));
    preset_ = new synth::Preset(synth::make_preset("facade", 1));
  }
  static void TearDownTestSuite() {
    delete data_;
    delete map_;
    delete preset_;
    fs::remove_all(dir_);
  }

  // Compares each target's depth along its pixel's ray (where the ray meets the target plane) with the
  // depth of the world's first hit.
  static TargetQuality measure(const ViewPlaneMaps& maps, const kernels::SplatCamera& c, double tolerance_m) {
    TargetQuality q;
    size_t seen = 0;
    const glm::dmat3 R_world_cam = glm::transpose(c.R_cam_world);
    const glm::dvec3 centre = -(R_world_cam * c.t_cam_world);
    for (uint32_t y = 0; y < c.height; ++y)
      for (uint32_t x = 0; x < c.width; ++x) {
        const glm::dvec3 ray_cam((x + 0.5 - c.cx) / c.fx, (y + 0.5 - c.cy) / c.fy, 1.0);
        const glm::dvec3 dir = R_world_cam * ray_cam;
        synth::Ray ray;
        ray.origin = Eigen::Vector3d(centre.x, centre.y, centre.z);
        ray.dir = Eigen::Vector3d(dir.x, dir.y, dir.z) / glm::length(dir);
        const auto hit = preset_->world.cast(ray, 0.1, 60.0);
        if (hit && hit->plane_id >= 0) ++seen;
        const size_t p = size_t{y} * c.width + x;
        if (maps.points[4 * p + 3] != 1.0f) continue;
        ++q.valid;
        const glm::dvec3 n(maps.normals[4 * p], maps.normals[4 * p + 1], maps.normals[4 * p + 2]);
        const glm::dvec3 P(maps.points[4 * p], maps.points[4 * p + 1], maps.points[4 * p + 2]);
        const double target_z = glm::dot(n, P) / glm::dot(n, ray_cam);
        const double true_z = hit ? hit->range_m / glm::length(dir) : 1e9;
        if (std::abs(target_z - true_z) > tolerance_m) ++q.off;
        else q.sq += (target_z - true_z) * (target_z - true_z) * glm::dot(n, ray_cam) * glm::dot(n, ray_cam);
      }
    q.coverage = seen > 0 ? static_cast<double>(q.valid) / static_cast<double>(seen) : 0.0;
    return q;
  }

  static inline fs::path dir_;
  static inline TrainingData* data_ = nullptr;
  static inline PlanarMap* map_ = nullptr;
  static inline synth::Preset* preset_ = nullptr;
};

TEST_F(FacadeTargets, TargetsLieOnTheSurfaceThePixelSees) {
  size_t valid = 0, off = 0;
  double coverage = 0, sq = 0;
  for (const TrainingView& v : data_->views) {
    const TargetQuality q = measure(project_planes(*map_, v.camera), v.camera, 0.05);
    valid += q.valid;
    off += q.off;
    coverage += q.coverage;
    sq += q.sq;
  }
  coverage /= static_cast<double>(data_->views.size());
  const double off_share = static_cast<double>(off) / static_cast<double>(valid);
  const double rms = std::sqrt(sq / static_cast<double>(valid - off));
  std::printf("targets: %zu over %zu views (%.1f%% of the pixels that see a plane), %.2f%% off the visible surface "
              "by > 5 cm, the rest %.1f mm RMS along the normal\n",
              valid, data_->views.size(), 100 * coverage, 100 * off_share, 1000 * rms);
  // Measured when written: 0.42% off, 3.1 mm RMS (the map's 15 mm range noise averaged by the plane fits).
  EXPECT_LT(off_share, 0.01);
  EXPECT_LT(rms, 0.006);
}

}  // namespace
}  // namespace litgs::host
