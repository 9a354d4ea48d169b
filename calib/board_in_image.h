// The holed board in one thermal image: the holes (the background seen through them is warmer or colder
// than the board) found as the inner contours of the board's region, each centre taken as its hole's
// intensity-weighted centroid, the board's pose from those centres and the intrinsics (PnP), and each
// centroid then corrected for the perspective and the lens, which move an ellipse's centroid off the
// projection of its circle's centre.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <string>
#include <vector>

#include "calib/holed_board.h"
#include "io/image.h"
#include "io/scene_types.h"

namespace litgs::calib {

struct BoardInImage {
  bool found = false;
  std::string why_not;
  std::vector<Eigen::Vector2d>
      centres_px;  // the projections of the holes' centres, in the board's hole order
  Eigen::Isometry3d T_cam_board = Eigen::Isometry3d::Identity();
  double pnp_rms_px = 0;  // the centres against the board's projection at that pose
  std::string polarity;   // "warm board" or "cold board"
};

// 8- or 16-bit frames (16-bit through the front end's percentile stretch). The board must be roughly
// upright in the image (its y axis within 45 degrees of the image's down) on a symmetric board.
BoardInImage find_board_in_image(const io::Image& image, const io::CameraIntrinsics& K,
                                 const HoledBoard& board);

// The pixel of a camera-frame point through K's lens distortion.
Eigen::Vector2d project_to_pixel(const io::CameraIntrinsics& K, const Eigen::Vector3d& p_cam);

}  // namespace litgs::calib
