#include "io/scene.h"

#include <algorithm>
#include <map>

#include "io/error.h"
#include "io/pcd.h"
#include "io/scene_text.h"
#include "io/scene_yaml.h"
#include "io/text.h"
#include "io/tum.h"

namespace litgs::io {
namespace fs = std::filesystem;
namespace {

std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return std::tolower(c); });
  return s;
}

// Files of `dir` with one of `extensions`, keyed by the timestamp their stem spells, sorted by time.
// IoError on a stem that is not a number, another extension, or a repeated timestamp.
std::vector<std::pair<double, fs::path>> timestamped_files(const fs::path& dir,
                                                           const std::vector<std::string>& extensions) {
  std::map<double, fs::path> files;
  for (const auto& e : fs::directory_iterator(dir)) {
    const fs::path p = e.path();
    if (!e.is_regular_file()) fail(p, 0, "not a regular file");
    if (std::find(extensions.begin(), extensions.end(), lower(p.extension().string())) == extensions.end())
      fail(p, 0, "unexpected file (the folder holds only <timestamp>" + extensions.front() + " files)");
    double t = 0;
    if (!try_parse_double(p.stem().string(), t)) fail(p, 0, "the file name is not a timestamp in seconds");
    const auto [it, inserted] = files.emplace(t, p);
    if (!inserted) fail(p, 0, "same timestamp as " + it->second.filename().string());
  }
  return {files.begin(), files.end()};
}

void check_image(const fs::path& path, const CameraIntrinsics& camera, const ImageInfo& info) {
  if (info.width != camera.width || info.height != camera.height)
    fail(path, 0,
         "image is " + std::to_string(info.width) + "x" + std::to_string(info.height) +
             ", scene.yaml camera is " + std::to_string(camera.width) + "x" + std::to_string(camera.height));
  if (info.bit_depth != camera.bit_depth)
    fail(path, 0,
         "image is " + std::to_string(info.bit_depth) + "-bit, scene.yaml says bit_depth " +
             std::to_string(camera.bit_depth));
  if (info.channels != 1)
    fail(path, 0, "thermal images have one channel, this one has " + std::to_string(info.channels));
}

void require(const fs::path& path, const char* what) {
  if (!fs::exists(path)) fail(path, 0, std::string("missing (") + what + ")");
}

}  // namespace

fs::path frame_file_name(double t_s, const std::string& extension) {
  return fs::path("thermal") / (format_double(t_s) + extension);
}

Scene read_scene(const fs::path& dir, const SceneReadOptions& options) {
  if (!fs::is_directory(dir)) fail(dir, 0, "not a scene directory");
  Scene scene;
  scene.config = read_scene_yaml(dir / "scene.yaml");

  const fs::path thermal = dir / "thermal";
  if (!fs::is_directory(thermal)) fail(thermal, 0, "missing (the thermal frames folder)");
  for (const auto& [t, path] : timestamped_files(thermal, {".png", ".tiff", ".tif"})) {
    if (options.check_images) check_image(path, scene.config.camera, read_image_info(path));
    scene.frames.push_back({t, fs::relative(path, dir)});
  }
  if (scene.frames.empty()) fail(thermal, 0, "no frames");

  require(dir / "poses.txt", "the trajectory");
  scene.poses = read_tum(dir / "poses.txt");

  const fs::path map = dir / "lidar/map.pcd";
  if (scene.config.has_lidar_map) {
    require(map, "scene.yaml says lidar_map: true");
    if (options.load_map) scene.map = read_pcd(map);
  } else if (fs::exists(map)) {
    fail(map, 0, "present although scene.yaml says lidar_map: false");
  }
  if (fs::is_directory(dir / "lidar/scans"))
    for (const auto& [t, path] : timestamped_files(dir / "lidar/scans", {".pcd"}))
      scene.scans.push_back({t, fs::relative(path, dir)});

  if (fs::exists(dir / "imu.csv")) scene.imu = read_imu_csv(dir / "imu.csv");
  if (fs::exists(dir / "anchors.txt")) scene.anchors = read_anchors(dir / "anchors.txt");
  if (fs::is_directory(dir / "gt")) {
    GroundTruth gt;
    if (fs::exists(dir / "gt/poses.txt")) gt.poses = read_tum(dir / "gt/poses.txt");
    if (fs::exists(dir / "gt/map.pcd")) gt.map = read_pcd(dir / "gt/map.pcd");
    if (fs::exists(dir / "gt/planes.txt")) gt.planes = read_planes(dir / "gt/planes.txt");
    scene.gt = std::move(gt);
  }
  return scene;
}

Image load_frame(const fs::path& dir, const Scene& scene, size_t i) {
  const fs::path path = dir / scene.frames.at(i).image;
  Image image = read_image(path);
  check_image(path, scene.config.camera, {image.width, image.height, image.channels, image.bit_depth});
  return image;
}

void write_scene(const fs::path& dir, const Scene& scene, const FrameImageSource& images,
                 const ScanSource& scans, const SceneWriteOptions& options) {
  const std::string problem = check_scene_config(scene.config);
  if (!problem.empty()) throw std::invalid_argument("write_scene: " + problem);
  if (options.image_extension != ".png" && options.image_extension != ".tiff")
    throw std::invalid_argument("write_scene: image_extension must be .png or .tiff");
  if (scene.frames.empty()) throw std::invalid_argument("write_scene: no frames");
  if (scene.config.has_lidar_map != scene.map.has_value())
    throw std::invalid_argument("write_scene: config.has_lidar_map disagrees with the presence of a map");
  if (!scene.scans.empty() && !scans)
    throw std::invalid_argument("write_scene: scans listed without a ScanSource");
  for (size_t i = 1; i < scene.frames.size(); ++i)
    if (!(scene.frames[i].t_s > scene.frames[i - 1].t_s))
      throw std::invalid_argument("write_scene: frame " + std::to_string(i) +
                                  " is not later than the one before");

  // Frames already in thermal/ under other names would silently join the scene: refuse to mix.
  fs::create_directories(dir / "thermal");
  for (const auto& e : fs::directory_iterator(dir / "thermal")) {
    bool ours = false;
    for (const auto& f : scene.frames)
      ours = ours || e.path().filename() == frame_file_name(f.t_s, options.image_extension).filename();
    if (!ours)
      throw std::invalid_argument(
          "write_scene: " + e.path().string() +
          " is not a frame of this scene (write into an empty or matching directory)");
  }
  const CameraIntrinsics& camera = scene.config.camera;
  for (size_t i = 0; i < scene.frames.size(); ++i) {
    const Image image = images(i);
    const fs::path path = dir / frame_file_name(scene.frames[i].t_s, options.image_extension);
    if (image.width != camera.width || image.height != camera.height || image.bit_depth != camera.bit_depth ||
        image.channels != 1)
      throw std::invalid_argument("write_scene: frame " + std::to_string(i) + " (" +
                                  path.filename().string() + ") is " + std::to_string(image.width) + "x" +
                                  std::to_string(image.height) + ", " + std::to_string(image.bit_depth) +
                                  "-bit, " + std::to_string(image.channels) + " channel(s); the camera is " +
                                  std::to_string(camera.width) + "x" + std::to_string(camera.height) + ", " +
                                  std::to_string(camera.bit_depth) + "-bit, 1 channel");
    write_image(path, image);
  }
  write_tum(dir / "poses.txt", scene.poses);
  const PcdWriteOptions pcd{.double_positions = options.double_precision_maps};
  if (scene.map) {
    fs::create_directories(dir / "lidar");
    write_pcd(dir / "lidar/map.pcd", *scene.map, pcd);
  }
  if (!scene.scans.empty()) {
    fs::create_directories(dir / "lidar/scans");
    for (size_t i = 0; i < scene.scans.size(); ++i)
      write_pcd(dir / "lidar/scans" / (format_double(scene.scans[i].t_s) + ".pcd"), scans(i), pcd);
  }
  if (!scene.imu.empty()) write_imu_csv(dir / "imu.csv", scene.imu);
  if (!scene.anchors.empty()) write_anchors(dir / "anchors.txt", scene.anchors);
  if (scene.gt) {
    fs::create_directories(dir / "gt");
    if (!scene.gt->poses.empty()) write_tum(dir / "gt/poses.txt", scene.gt->poses);
    if (scene.gt->map) write_pcd(dir / "gt/map.pcd", *scene.gt->map, pcd);
    if (!scene.gt->planes.empty()) write_planes(dir / "gt/planes.txt", scene.gt->planes);
  }
  write_scene_yaml(dir / "scene.yaml", scene.config);  // last: a scene.yaml means the rest is there
}

}  // namespace litgs::io
