// Initialization from points with covariances: a given covariance becomes the Gaussian's axes and lengths,
// LiDAR plane points become discs on their plane, and bad covariance fields are errors that name the file
// and the point.
#include <gtest/gtest.h>
#include <unistd.h>

#include <Eigen/Geometry>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>

#include "host/train/init_gaussians.h"

namespace litgs::host {
namespace {

namespace fs = std::filesystem;

// The covariance a Gaussian of the model renders with: R diag(exp(log_scale))^2 R^T, quaternion w-first.
Eigen::Matrix3d model_covariance(const kernels::GaussianModel& m, size_t i) {
  const Eigen::Quaterniond q(m.quats[4 * i], m.quats[4 * i + 1], m.quats[4 * i + 2], m.quats[4 * i + 3]);
  const Eigen::Matrix3d R = q.normalized().toRotationMatrix();
  Eigen::Vector3d s;
  for (int a = 0; a < 3; ++a) s[a] = std::exp(static_cast<double>(m.log_scales[3 * i + a]));
  return R * s.cwiseAbs2().asDiagonal() * R.transpose();
}

Eigen::Matrix3d random_covariance(std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-1.0, 1.0), len(0.01, 0.3);
  const Eigen::Quaterniond q = Eigen::Quaterniond(u(rng), u(rng), u(rng), u(rng)).normalized();
  const Eigen::Vector3d s(len(rng), len(rng), len(rng));
  return q.toRotationMatrix() * s.cwiseAbs2().asDiagonal() * q.toRotationMatrix().transpose();
}

TEST(InitCovariances, AGivenCovarianceBecomesTheGaussiansShape) {
  std::mt19937 rng(5);
  std::vector<Eigen::Vector3d> pts;
  std::vector<Eigen::Matrix3d> covs;
  for (int i = 0; i < 50; ++i) {
    pts.emplace_back(i * 0.1, 0.0, 2.0);
    covs.push_back(random_covariance(rng));
  }
  const kernels::GaussianModel m = init_from_points(pts, TrainingData{}, InitOptions{}, covs);
  for (size_t i = 0; i < pts.size(); ++i) {
    const Eigen::Matrix3d back = model_covariance(m, i);
    EXPECT_LT((back - covs[i]).norm(), 2e-6 * covs[i].norm() + 1e-9) << "point " << i;
  }
}

TEST(InitCovariances, WithoutCovariancesGaussiansAreIsotropic) {
  const std::vector<Eigen::Vector3d> pts = {{0, 0, 2}, {0.1, 0, 2}, {0, 0.2, 2}, {0.3, 0.3, 2}};
  const kernels::GaussianModel m = init_from_points(pts, TrainingData{}, InitOptions{});
  const std::vector<double> scales = neighbour_scales(pts, InitOptions{});
  for (size_t i = 0; i < pts.size(); ++i) {
    const Eigen::Matrix3d expect = scales[i] * scales[i] * Eigen::Matrix3d::Identity();
    EXPECT_LT((model_covariance(m, i) - expect).norm(), 1e-6 * expect.norm()) << "point " << i;
  }
}

TEST(InitCovariances, PlanePointsBecomeDiscsOnTheirPlane) {
  const Eigen::Vector3f n = Eigen::Vector3f(1, 2, 2).normalized();
  const std::vector<double> scales = {0.1, 0.05};
  const auto covs = surfel_covariances(scales, {n, n}, {1, 0}, 0.1);
  // Along the normal: (0.1 * 0.1)^2; in the plane: 0.1^2; the non-planar point: a sphere.
  const Eigen::Vector3d nd = n.cast<double>().normalized();
  EXPECT_NEAR(nd.dot(covs[0] * nd), 1e-4, 1e-12);
  const Eigen::Vector3d in_plane = nd.cross(Eigen::Vector3d::UnitX()).normalized();
  EXPECT_NEAR(in_plane.dot(covs[0] * in_plane), 1e-2, 1e-12);
  EXPECT_LT((covs[1] - 0.0025 * Eigen::Matrix3d::Identity()).norm(), 1e-15);
  EXPECT_THROW(surfel_covariances(scales, {n}, {1, 0}, 0.1), std::invalid_argument);
  EXPECT_THROW(surfel_covariances(scales, {n, n}, {1, 0}, 0.0), std::invalid_argument);
}

TEST(InitCovariances, CountMismatchIsAnError) {
  const std::vector<Eigen::Vector3d> pts = {{0, 0, 2}, {0.1, 0, 2}};
  const std::vector<Eigen::Matrix3d> one = {Eigen::Matrix3d::Identity()};
  EXPECT_THROW(init_from_points(pts, TrainingData{}, InitOptions{}, one), std::invalid_argument);
}

class CovariancePly : public ::testing::Test {
 protected:
  void SetUp() override {
    path_ = fs::temp_directory_path() / ("litgs-init-cov-" + std::to_string(::getpid()) + ".ply");
  }
  void TearDown() override { fs::remove(path_); }
  void write(const std::string& properties, const std::vector<std::string>& rows) {
    std::ofstream f(path_);
    f << "ply\nformat ascii 1.0\nelement vertex " << rows.size() << "\nproperty float x\nproperty float y\n"
      << "property float z\n"
      << properties << "end_header\n";
    for (const auto& r : rows) f << r << "\n";
  }
  fs::path path_;
};

const char* kSixFields =
    "property float cov_xx\nproperty float cov_xy\nproperty float cov_xz\nproperty float cov_yy\n"
    "property float cov_yz\nproperty float cov_zz\n";

TEST_F(CovariancePly, SixFieldsAreReadAsTheUpperTriangle) {
  write(kSixFields, {"1 2 3 0.04 0.01 0 0.09 0 0.01", "0 0 1 1 0 0 1 0 1"});
  const InitPoints p = load_points(path_, Eigen::Vector3d(1, 0, 0));
  ASSERT_EQ(p.positions.size(), 2u);
  EXPECT_EQ(p.positions[0], Eigen::Vector3d(0, 2, 3));  // the recentring offset applies
  ASSERT_EQ(p.covariances.size(), 2u);
  EXPECT_NEAR(p.covariances[0](0, 0), 0.04, 1e-7);
  EXPECT_NEAR(p.covariances[0](1, 0), 0.01, 1e-7);
  EXPECT_NEAR(p.covariances[0](0, 1), 0.01, 1e-7);
  EXPECT_NEAR(p.covariances[0](1, 1), 0.09, 1e-7);
  EXPECT_NEAR(p.covariances[0](2, 2), 0.01, 1e-7);
}

TEST_F(CovariancePly, NotPositiveDefiniteNamesThePoint) {
  write(kSixFields, {"0 0 1 1 0 0 1 0 1", "0 0 1 1 2 0 1 0 1"});  // |xy| > sqrt(xx yy)
  try {
    load_points(path_, Eigen::Vector3d::Zero());
    FAIL() << "expected an error";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("point 1"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("positive definite"), std::string::npos) << e.what();
  }
}

TEST_F(CovariancePly, SomeButNotAllFieldsIsAnError) {
  write("property float cov_xx\nproperty float cov_yy\n", {"0 0 1 1 1"});
  EXPECT_THROW(load_points(path_, Eigen::Vector3d::Zero()), std::invalid_argument);
}

}  // namespace
}  // namespace litgs::host
