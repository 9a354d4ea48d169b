// The fixture the training tests share: the small synthetic facade (12 frames at 64x48, every 4th held out),
// planes fitted to its LiDAR map, and 3,000 of its map points as the initial model (SH degree 1), made once
// per test suite in a temporary folder.
#pragma once

#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <functional>
#include <random>
#include <string>
#include <vector>

#include "gpu_test.h"
#include "host/synth/synth.h"
#include "host/train/init_gaussians.h"
#include "host/train/lidar_planes.h"
#include "host/train/training_data.h"
#include "io/scene.h"

namespace litgs::testing {

class SmallTrainingSceneTest : public GpuTest {
 protected:
  // Call from the suite's SetUpTestSuite. `name` prefixes the temporary folder; `edit_scene` may change the
  // generated scene folder (root_ / "scene") before it is loaded; `edit_options` the generator's options.
  static void set_up_scene(const std::string& name,
                           const std::function<void(const std::filesystem::path&)>& edit_scene = {},
                           const std::function<void(host::synth::SynthOptions&)>& edit_options = {}) {
    GpuTest::SetUpTestSuite();
    root_ = std::filesystem::temp_directory_path() / (name + "-" + std::to_string(::getpid()));
    std::filesystem::remove_all(root_);
    host::synth::SynthOptions s;
    s.frames = 12;
    s.width = 64;
    s.height = 48;
    s.out = root_ / "scene";
    if (edit_options) edit_options(s);
    host::synth::generate_synthetic_scene(s);
    if (edit_scene) edit_scene(s.out);
    host::TrainingDataOptions d;
    d.holdout_every = 4;
    data_ = new host::TrainingData(host::load_training_data(s.out, d));
    const io::Scene scene = io::read_scene(s.out);
    std::vector<Eigen::Vector3d> pts = scene.map->positions;
    planes_ = new host::PlanarMap(host::fit_planes(pts, host::PlaneFitOptions{}));
    std::mt19937 rng(1);
    std::shuffle(pts.begin(), pts.end(), rng);
    pts.resize(3000);
    host::InitOptions init;
    init.sh_degree = 1;
    initial_ = new kernels::GaussianModel(host::init_from_points(pts, *data_, init));
  }
  static void TearDownTestSuite() {
    delete data_;
    delete planes_;
    delete initial_;
    data_ = nullptr;
    planes_ = nullptr;
    initial_ = nullptr;
    std::filesystem::remove_all(root_);
    GpuTest::TearDownTestSuite();
  }

  static inline std::filesystem::path root_;
  static inline host::TrainingData* data_ = nullptr;
  static inline host::PlanarMap* planes_ = nullptr;
  static inline kernels::GaussianModel* initial_ = nullptr;
};

}  // namespace litgs::testing
