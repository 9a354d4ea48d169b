#include "calib/extrinsic_views.h"

#include <map>
#include <stdexcept>

#include "io/image.h"
#include "io/pcd.h"
#include "io/ply_points.h"

namespace litgs::calib {
namespace {

namespace fs = std::filesystem;

std::map<std::string, fs::path> files_by_stem(const fs::path& dir, const std::vector<std::string>& extensions,
                                              const std::string& what) {
  if (!fs::is_directory(dir)) throw std::invalid_argument(dir.string() + ": not a folder (" + what + ")");
  std::map<std::string, fs::path> out;
  for (const auto& e : fs::directory_iterator(dir)) {
    const std::string ext = e.path().extension().string();
    for (const std::string& x : extensions)
      if (e.is_regular_file() && ext == x) out[e.path().stem().string()] = e.path();
  }
  if (out.empty()) {
    std::string list;
    for (const std::string& x : extensions) list += (list.empty() ? "" : " or ") + x;
    throw std::invalid_argument(dir.string() + ": no " + list + " files (" + what + ")");
  }
  return out;
}

}  // namespace

std::vector<ExtrinsicView> find_boards(const fs::path& images, const fs::path& scans,
                                       const io::CameraIntrinsics& K, const HoledBoard& board,
                                       const BoardInScanOptions& scan_options,
                                       const std::function<void(const ExtrinsicView&)>& on_view) {
  board.check();
  scan_options.check();
  const auto image_files = files_by_stem(images, {".png", ".tif", ".tiff"}, "the images");
  const auto scan_files = files_by_stem(scans, {".pcd", ".ply"}, "the scans");
  std::map<std::string, std::pair<fs::path, fs::path>> pairs;
  for (const auto& [stem, path] : image_files) pairs[stem].first = path;
  for (const auto& [stem, path] : scan_files) pairs[stem].second = path;
  std::vector<ExtrinsicView> views;
  for (const auto& [stem, files] : pairs) {
    ExtrinsicView v;
    v.name = stem;
    const auto& [image_path, scan_path] = files;
    if (image_path.empty()) v.image.why_not = "no image named " + stem + " in " + images.string();
    if (scan_path.empty()) v.scan.why_not = "no scan named " + stem + " in " + scans.string();
    if (!image_path.empty()) {
      try {
        v.image = find_board_in_image(io::read_image(image_path), K, board);
      } catch (const std::exception& e) {
        v.image.why_not = e.what();
      }
    }
    if (!scan_path.empty()) {
      try {
        const io::PointCloud cloud =
            scan_path.extension() == ".pcd" ? io::read_pcd(scan_path) : io::read_ply_points(scan_path);
        v.scan = find_board_in_scan(cloud.positions, board, scan_options);
      } catch (const std::exception& e) {
        v.scan.why_not = e.what();
      }
    }
    if (on_view) on_view(v);
    views.push_back(std::move(v));
  }
  return views;
}

}  // namespace litgs::calib
