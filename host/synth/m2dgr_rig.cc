#include "host/synth/m2dgr_rig.h"

#include <stdexcept>

#include "io/m2dgr_calib.h"

namespace litgs::host::synth {

void apply_m2dgr_rig(const M2dgrRig& rig, std::optional<int> width, std::optional<int> height, Preset& p) {
  const io::M2dgrCamera cam = io::read_m2dgr_camera(rig.file, rig.camera_block);
  const io::M2dgrCamera imu = io::read_m2dgr_camera(rig.file, rig.imu_block);
  const std::string where = "synth: --rig " + rig.file.string() + ": block '";
  if (!cam.has_extrinsic || !cam.has_intrinsics || cam.width <= 0 || cam.height <= 0)
    throw std::invalid_argument(where + rig.camera_block +
                                "' needs an extrinsic, an intrinsic and an image size");
  if (!imu.has_extrinsic)
    throw std::invalid_argument(where + rig.imu_block + "' has no extrinsic [to LIDAR]");

  const Eigen::Isometry3d T_lidar_cam(cam.T_lidar_cam), T_lidar_imu(imu.T_lidar_cam);
  p.T_imu_lidar = T_lidar_imu.inverse();
  p.T_imu_cam = p.T_imu_lidar * T_lidar_cam;

  io::CameraIntrinsics K;
  K.width = width.value_or(cam.width);
  K.height = height.value_or(cam.height);
  // Scaling the image keeps the field of view: pixel centres map as (u + 0.5) * s - 0.5.
  const double sx = static_cast<double>(K.width) / cam.width, sy = static_cast<double>(K.height) / cam.height;
  K.fx = cam.fx * sx;
  K.fy = cam.fy * sy;
  K.cx = (cam.cx + 0.5) * sx - 0.5;
  K.cy = (cam.cy + 0.5) * sy - 0.5;
  K.distortion = cam.distortion;
  p.camera.width = K.width;
  p.camera.height = K.height;
  p.camera.calibrated = K;
}

}  // namespace litgs::host::synth
