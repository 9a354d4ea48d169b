// The views of `calib extrinsic`: images and scans paired by file name (view_000.png with view_000.pcd), the
// board found in each. A file that cannot be read, or without its partner, makes a view without the board
// that says why, rather than stopping the calibration.
#pragma once

#include <filesystem>
#include <functional>
#include <vector>

#include "calib/extrinsic.h"

namespace litgs::calib {

// Images: .png, .tif, .tiff; scans: .pcd or .ply (x y z in the LiDAR frame). std::invalid_argument when a
// folder holds none. `on_view` (if set) is called with each view as it is done.
std::vector<ExtrinsicView> find_boards(const std::filesystem::path& images,
                                       const std::filesystem::path& scans, const io::CameraIntrinsics& K,
                                       const HoledBoard& board, const BoardInScanOptions& scan_options,
                                       const std::function<void(const ExtrinsicView&)>& on_view = {});

}  // namespace litgs::calib
