#include "io/export_bag.h"

#include <stdexcept>

#include "io/atomic_file.h"
#include "io/error.h"
#include "io/export_scene.h"
#include "io/pcd.h"
#include "io/scene.h"

namespace litgs::io {
namespace fs = std::filesystem;

void BagExportOptions::check() const {
  if (scene.empty()) throw std::invalid_argument("scene: required");
  if (out.empty()) throw std::invalid_argument("out: required");
  if (!fs::is_directory(scene)) throw std::invalid_argument("scene: not a directory: " + scene.string());
  if (topics.thermal.empty()) throw std::invalid_argument("topics.thermal: the frames need a topic");
}

BagExportReport export_bag(const BagExportOptions& o) {
  o.check();
  if (!ros_bag_writer_available())
    fail(o.out, 0, "this build cannot write ROS bags (rosbag_storage was not found when it was built)");
  const Scene scene = read_scene(o.scene, {.check_images = false, .load_map = false});
  if (!o.topics.lidar.empty() && scene.scans.empty())
    fail(o.scene / "lidar/scans", 0, "the scene has no LiDAR scans to write (leave the LiDAR topic empty)");
  const Eigen::Vector3d offset = o.recentred ? Eigen::Vector3d::Zero() : scene.config.world_offset_m;

  BagExportReport report;
  AtomicFile file(o.out);
  {
    RosBagWriter bag(file.temp_path());
    // Interleaved by time as a recorder writes them; the bag's index orders them for readers anyway.
    size_t next_scan = 0;
    for (size_t i = 0; i < scene.frames.size(); ++i) {
      for (; !o.topics.lidar.empty() && next_scan < scene.scans.size() &&
             scene.scans[next_scan].t_s <= scene.frames[i].t_s;
           ++next_scan, ++report.scans)
        bag.cloud(o.topics.lidar, scene.scans[next_scan].t_s,
                  read_pcd(o.scene / scene.scans[next_scan].file));
      bag.image(o.topics.thermal, scene.frames[i].t_s, load_frame(o.scene, scene, i));
      ++report.frames;
    }
    for (; !o.topics.lidar.empty() && next_scan < scene.scans.size(); ++next_scan, ++report.scans)
      bag.cloud(o.topics.lidar, scene.scans[next_scan].t_s, read_pcd(o.scene / scene.scans[next_scan].file));
    if (!o.topics.imu.empty())
      for (const ImuSample& s : scene.imu) {
        bag.imu(o.topics.imu, s);
        ++report.imu;
      }
    if (!o.topics.odom.empty())
      for (TumPose p : imu_trajectory(scene.config, scene.poses, o.scene / "poses.txt")) {
        p.p_world += offset;
        bag.odom(o.topics.odom, p);
        ++report.odometry;
      }
    bag.close();
  }
  file.commit();
  return report;
}

}  // namespace litgs::io
