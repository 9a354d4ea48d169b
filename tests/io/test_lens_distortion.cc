// The lens models against OpenCV's (an independent implementation): distortion as projectPoints and
// fisheye::projectPoints compute it, undistortion as its exact inverse, and the named hard cases: M2DGR's
// thermal lens (k1 = -0.436, strong barrel) to the image corners, and points beyond a model's range.
#include <gtest/gtest.h>

#include <opencv2/calib3d.hpp>
#include <vector>

#include "io/lens_distortion.h"

namespace litgs::io {
namespace {

// M2DGR's thermal camera (tests/data/m2dgr/calibration_results.txt, block Cam-thermal).
CameraIntrinsics m2dgr_thermal() {
  CameraIntrinsics k;
  k.width = 640;
  k.height = 512;
  k.fx = 435.836180277211;
  k.fy = 435.909430631362;
  k.cx = 324.45275323285;
  k.cy = 255.55432008219;
  k.distortion = {-0.436107594318055, 0.166413618922992, 0, 0};
  return k;
}

// OpenCV's projection of a camera-frame point (pinhole with radtan, or fisheye), in pixels.
Eigen::Vector2d opencv_project(const CameraIntrinsics& k, const Eigen::Vector3d& p) {
  const cv::Matx33d K(k.fx, 0, k.cx, 0, k.fy, k.cy, 0, 0, 1);
  std::vector<cv::Point2d> out;
  if (k.model == CameraModel::kEquidistant)
    cv::fisheye::projectPoints(std::vector<cv::Point3d>{{p.x(), p.y(), p.z()}}, out, cv::Vec3d(0, 0, 0),
                               cv::Vec3d(0, 0, 0), K, k.distortion);
  else
    cv::projectPoints(std::vector<cv::Point3d>{{p.x(), p.y(), p.z()}}, cv::Vec3d(0, 0, 0), cv::Vec3d(0, 0, 0),
                      K, k.distortion, out);
  return {out[0].x, out[0].y};
}

TEST(LensDistortion, DistortionIsOpenCvs) {
  CameraIntrinsics radtan = m2dgr_thermal();
  radtan.distortion = {-0.3, 0.1, 0.002, -0.001, 0.01};  // tangential and k3 too
  CameraIntrinsics fisheye = m2dgr_thermal();
  fisheye.model = CameraModel::kEquidistant;
  fisheye.distortion = {0.05, -0.02, 0.004, -0.001};
  for (const CameraIntrinsics& k : {radtan, fisheye})
    for (const Eigen::Vector2d& n : {Eigen::Vector2d(0.0, 0.0), Eigen::Vector2d(0.3, -0.2),
                                     Eigen::Vector2d(-0.7, 0.55), Eigen::Vector2d(1.1, 0.9)}) {
      const Eigen::Vector2d d = distort_normalized(k, n);
      const Eigen::Vector2d expected = opencv_project(k, {n.x(), n.y(), 1.0});
      EXPECT_NEAR(k.fx * d.x() + k.cx, expected.x(), 1e-9);
      EXPECT_NEAR(k.fy * d.y() + k.cy, expected.y(), 1e-9);
    }
}

TEST(LensDistortion, M2dgrThermalRaysReprojectToTheirPixelsUpToTheCorners) {
  const CameraIntrinsics k = m2dgr_thermal();
  int corners_far_from_pinhole = 0;
  for (const double u : {0.0, 1.0, 100.5, 324.0, 500.0, 639.0})
    for (const double v : {0.0, 77.0, 255.5, 400.0, 511.0}) {
      const auto ray = pixel_ray(k, u, v);
      ASSERT_TRUE(ray) << u << " " << v;
      const Eigen::Vector2d back = opencv_project(k, *ray);
      EXPECT_NEAR(back.x(), u, 1e-6);
      EXPECT_NEAR(back.y(), v, 1e-6);
      // Strong barrel: a corner's ray is far outside where a pinhole would put it.
      const double pinhole_x = (u - k.cx) / k.fx;
      if (std::abs(ray->x() - pinhole_x) > 0.2) ++corners_far_from_pinhole;
    }
  EXPECT_GT(corners_far_from_pinhole, 3);
}

TEST(LensDistortion, FisheyeRaysReprojectToTheirPixels) {
  CameraIntrinsics k = m2dgr_thermal();
  k.model = CameraModel::kEquidistant;
  k.distortion = {0.05, -0.02, 0.004, -0.001};
  for (const double u : {0.0, 320.0, 639.0})
    for (const double v : {0.0, 511.0, 200.0}) {
      const auto ray = pixel_ray(k, u, v);
      ASSERT_TRUE(ray);
      const Eigen::Vector2d back = opencv_project(k, *ray);
      EXPECT_NEAR(back.x(), u, 1e-6);
      EXPECT_NEAR(back.y(), v, 1e-6);
    }
}

TEST(LensDistortion, APointBeyondTheModelsRangeHasNoRay) {
  // r_d = r (1 + k1 r^2) with k1 = -0.5 peaks at r = 1/sqrt(1.5), r_d = 0.544: nothing distorts to 0.8.
  CameraIntrinsics k = m2dgr_thermal();
  k.distortion = {-0.5, 0, 0, 0};
  EXPECT_FALSE(undistort_normalized(k, {0.8, 0.0}));
  EXPECT_TRUE(undistort_normalized(k, {0.5, 0.0}));
  // No distortion: the point itself.
  k.distortion.clear();
  const auto same = undistort_normalized(k, {0.8, -0.3});
  ASSERT_TRUE(same);
  EXPECT_EQ(*same, Eigen::Vector2d(0.8, -0.3));
}

}  // namespace
}  // namespace litgs::io
