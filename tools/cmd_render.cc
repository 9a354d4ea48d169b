// `litgs-engine render`: one view of a 3DGS PLY model, on the device (or with the double-precision CPU
// reference), to PNG: the image, and optionally expected depth and accumulated alpha.
//
// Frames: poses are in the scene's frame, the frame of its poses.txt (recentred: original world -
// world_offset_m), whenever the scene's offset is known (--scene, or the PLY's litgs_scene_world_offset_m
// header line that train writes); the model is moved into that frame in double precision before it is
// rendered, so a model trained on a scene renders at the scene's poses whatever frame its PLY is in
// (host/train/output_frame.h). --pose-frame original takes poses in original world coordinates (export
// tum/colmap's default), --pose-frame model in the PLY's own coordinates (the only choice for a PLY from
// elsewhere without --scene).
#include <CLI/CLI.hpp>
#include <algorithm>
#include <cmath>
#include <fstream>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>
#include <stdexcept>

#include "engine/context.h"
#include "host/train/level_plan.h"
#include "host/train/output_frame.h"
#include "host/train/training_data.h"
#include "io/gaussian_ply.h"
#include "io/image.h"
#include "io/scene.h"
#include "kernels/splat/rasterizer.h"
#include "kernels/splat/reference.h"
#include "tools/commands.h"
#include "tools/render_view.h"

namespace litgs::tools {
namespace {

struct RenderOptions {
  std::string model;               // 3DGS PLY
  std::string camera_json;         // camera file (see camera_from_json), or the flags below
  std::vector<double> pose;        // qw qx qy qz tx ty tz: world-to-camera, COLMAP's images.txt order
  std::vector<double> intrinsics;  // fx fy cx cy in pixels
  uint32_t width = 0, height = 0;
  int sh_degree = -1;  // -1: the model's degree
  std::string out;     // image PNG: 8-bit, or 16-bit with --bit-depth 16; values clamped to [0, 1]
  int bit_depth = 8;
  std::string depth_out;            // expected depth, 16-bit PNG in units of 1/depth_scale metres
  double depth_scale = 1000.0;      // depth PNG value per metre (1000: millimetres, up to 65.535 m)
  std::string alpha_out;            // accumulated alpha, 8-bit PNG
  bool reference = false;           // render with the double-precision CPU reference instead of the device
  std::string scene;                // scene directory: its world_offset_m, and its cameras for --time
  std::string time;                 // render the scene's view at this time (s), as training sees it
  double downscale = 1.0;           // --time: the training resolution (train's --downscale)
  std::string poses = "estimated";  // --time: estimated (poses.txt) | truth (gt/poses.txt)
  std::string pose_frame = "auto";  // auto | scene | original | model (see the top of this file)
  std::string levels;               // train's levels.json: the level of --time, and the stretch for --counts
  bool counts = false;              // 16-bit raw counts (the inverse of the stretch) instead of [0, 1] scaled
};

// Before anything is rendered: --levels and --counts need their companions.
void check_level_options(const RenderOptions& o) {
  if (o.counts && o.levels.empty())
    throw std::invalid_argument("--counts needs --levels (train's levels.json holds the stretch window)");
  if (o.counts && o.bit_depth != 16)
    throw std::invalid_argument("--counts writes 16-bit raw counts: give --bit-depth 16");
  if (!o.levels.empty() && o.time.empty())
    throw std::invalid_argument("--levels applies the level of a scene time: give --scene and --time");
}

// The level of --time from train's levels.json applied to the render (x' = g v x + o), and with --counts the
// values turned back into the raw frames' counts: low + x' (high - low). Returns the scale to_image takes.
double level_and_counts(const RenderOptions& o, const kernels::SplatCamera& camera,
                        std::vector<float>& image) {
  if (o.levels.empty()) return o.bit_depth == 16 ? 65535.0 : 255.0;
  const host::LevelTable table = host::read_level_table(o.levels);
  const kernels::LevelGeometry g{camera.width, camera.height, 1, static_cast<float>(camera.cx),
                                 static_cast<float>(camera.cy)};
  if (image.size() != size_t{camera.width} * camera.height)
    throw std::invalid_argument("--levels: the level model is for one-channel (thermal) models");
  image = host::apply_level(image, g, table.at_time(std::stod(o.time)), table.vignetting());
  if (!o.counts) return o.bit_depth == 16 ? 65535.0 : 255.0;
  // to_image scales [0, 1]: shift to counts first, then scale by 1.
  for (float& v : image)
    v = static_cast<float>(table.stretch_low + v * (table.stretch_high - table.stretch_low));
  return 1.0;
}

// {"width": W, "height": H, "fx": .., "fy": .., "cx": .., "cy": ..,
//  "q_cam_world": [qw, qx, qy, qz], "t_cam_world": [tx, ty, tz]}  (p_cam = R p_world + t, as COLMAP)
kernels::SplatCamera camera_from_json(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error(path + ": cannot open the camera file");
  nlohmann::json j;
  try {
    in >> j;
    kernels::SplatCamera c;
    c.width = j.at("width").get<uint32_t>();
    c.height = j.at("height").get<uint32_t>();
    c.fx = j.at("fx").get<double>();
    c.fy = j.at("fy").get<double>();
    c.cx = j.at("cx").get<double>();
    c.cy = j.at("cy").get<double>();
    const auto q = j.at("q_cam_world").get<std::vector<double>>();
    const auto t = j.at("t_cam_world").get<std::vector<double>>();
    if (q.size() != 4 || t.size() != 3)
      throw std::invalid_argument("q_cam_world needs 4 values, t_cam_world 3");
    c.R_cam_world = rotation_from_quat(q[0], q[1], q[2], q[3]);
    c.t_cam_world = {t[0], t[1], t[2]};
    return c;
  } catch (const std::exception& e) {
    throw std::runtime_error(path + ": bad camera file: " + e.what());
  }
}

// The camera of the scene's view at time `text` (seconds), as training builds it.
kernels::SplatCamera scene_camera(const RenderOptions& o, const io::Scene& scene) {
  if (!o.camera_json.empty() || !o.pose.empty())
    throw std::invalid_argument("give --time, or --camera, or --pose: not more than one");
  if (o.pose_frame != "auto" && o.pose_frame != "scene")
    throw std::invalid_argument("--time renders the scene's camera, in the scene frame: --pose-frame " +
                                o.pose_frame + " does not apply");
  if (o.poses != "estimated" && o.poses != "truth")
    throw std::invalid_argument("--poses must be estimated or truth, not '" + o.poses + "'");
  double t = 0;
  try {
    size_t used = 0;
    t = std::stod(o.time, &used);
    if (used != o.time.size()) throw std::invalid_argument("trailing characters");
  } catch (const std::exception&) {
    throw std::invalid_argument("--time '" + o.time + "' is not a number of seconds");
  }
  host::TrainingDataOptions data;
  data.downscale = o.downscale;
  data.true_poses = o.poses == "truth";
  return host::training_camera(o.scene, scene, t, data);
}

void run_render(const RenderOptions& o) {
  if (!o.time.empty() && o.scene.empty())
    throw std::invalid_argument("--time needs --scene (the scene's cameras)");
  check_level_options(o);
  std::optional<io::Scene> scene;
  if (!o.scene.empty()) {
    io::SceneReadOptions read;
    read.check_images = false;
    read.load_map = false;
    scene = io::read_scene(o.scene, read);
  }
  kernels::SplatCamera camera;
  if (!o.time.empty()) {
    camera = scene_camera(o, *scene);
  } else if (!o.camera_json.empty()) {
    camera = camera_from_json(o.camera_json);
  } else {
    if (o.pose.size() != 7 || o.intrinsics.size() != 4 || o.width == 0 || o.height == 0)
      throw std::invalid_argument(
          "give --camera FILE, or --pose (7 values) --intrinsics (4) --width --height");
    camera.R_cam_world = rotation_from_quat(o.pose[0], o.pose[1], o.pose[2], o.pose[3]);
    camera.t_cam_world = {o.pose[4], o.pose[5], o.pose[6]};
    camera.fx = o.intrinsics[0];
    camera.fy = o.intrinsics[1];
    camera.cx = o.intrinsics[2];
    camera.cy = o.intrinsics[3];
    camera.width = o.width;
    camera.height = o.height;
  }
  if (o.bit_depth != 8 && o.bit_depth != 16) throw std::invalid_argument("--bit-depth must be 8 or 16");
  std::optional<Eigen::Vector3d> scene_offset;
  if (scene) scene_offset = scene->config.world_offset_m;
  FramedModel framed = load_framed_model(o.model, o.pose_frame, scene_offset, o.scene);
  const kernels::GaussianModel& model = framed.model;
  camera.sh_degree = o.sh_degree < 0 ? model.sh_degree : static_cast<uint32_t>(o.sh_degree);
  camera.check();

  std::vector<float> image, depth, alpha;
  uint64_t intersections = 0, culled = 0, walks_cut = 0;
  if (o.reference) {
    const auto r = kernels::reference_forward(model, camera);
    image.assign(r.image.begin(), r.image.end());
    depth.assign(r.depth.begin(), r.depth.end());
    alpha.assign(r.alpha.begin(), r.alpha.end());
    intersections = r.intersections;
    culled = r.culled_nonfinite;
  } else {
    engine::Context context;
    kernels::DeviceGaussians gaussians(context, model);
    kernels::Rasterizer rasterizer(context, model.channels);
    rasterizer.forward(gaussians, camera);
    const auto r = rasterizer.download_images();
    image = r.image;
    depth = r.depth;
    alpha = r.alpha;
    intersections = r.intersections;
    culled = r.culled_nonfinite;
    walks_cut = r.walks_cut_short;
  }
  const double full = level_and_counts(o, camera, image);
  io::write_image(o.out, to_image(image, camera.width, camera.height, model.channels, o.bit_depth, full));
  if (!o.depth_out.empty())
    io::write_image(o.depth_out, to_image(depth, camera.width, camera.height, 1, 16, o.depth_scale));
  if (!o.alpha_out.empty())
    io::write_image(o.alpha_out, to_image(alpha, camera.width, camera.height, 1, 8, 255.0));
  const std::string frame_text = framed.frame == "scene"
                                     ? "scene frame (world_offset_m " + vector_text(framed.frame_offset) + ")"
                                 : framed.frame == "original" ? "original world frame"
                                                              : "model's frame";
  std::cout << "render: " << model.size() << " Gaussians, " << intersections << " tile intersections, "
            << camera.width << "x" << camera.height << (o.reference ? " (CPU reference)" : "")
            << ", poses in the " << frame_text << " -> " << o.out << "\n";
  if (culled > 0)
    std::cout << "render: warning: " << culled
              << " Gaussians culled for a non-finite parameter (not drawn)\n";
  if (walks_cut > 0)
    std::cout << "render: warning: " << walks_cut
              << " tile-list walks cut short by the driver's loop limit (the render is incomplete there)\n";
}

}  // namespace

void add_render_command(CLI::App& app) {
  auto o = std::make_shared<RenderOptions>();
  CLI::App* cmd = app.add_subcommand("render", "Render one view of a 3DGS PLY model to PNG");
  cmd->add_option("--model", o->model, "3DGS PLY model")->required()->check(CLI::ExistingFile);
  cmd->add_option("--camera", o->camera_json, "Camera JSON: width height fx fy cx cy q_cam_world t_cam_world")
      ->check(CLI::ExistingFile);
  cmd->add_option("--pose", o->pose,
                  "qw qx qy qz tx ty tz, world-to-camera (COLMAP images.txt order), in --pose-frame's world")
      ->expected(7);
  cmd->add_option("--intrinsics", o->intrinsics, "fx fy cx cy in pixels")->expected(4);
  cmd->add_option("--width", o->width, "Image width");
  cmd->add_option("--height", o->height, "Image height");
  cmd->add_option("--sh-degree", o->sh_degree, "Active SH degree (default: the model's)");
  cmd->add_option("--out", o->out, "Image PNG (values in [0, 1] scaled to the bit depth)")->required();
  cmd->add_option("--bit-depth", o->bit_depth, "8 or 16")->capture_default_str();
  cmd->add_option("--depth", o->depth_out, "Expected depth as 16-bit PNG (see --depth-scale)");
  cmd->add_option("--depth-scale", o->depth_scale, "Depth PNG value per metre")->capture_default_str();
  cmd->add_option("--alpha", o->alpha_out, "Accumulated alpha as 8-bit PNG");
  cmd->add_flag("--reference", o->reference, "Use the double-precision CPU reference (slow)");
  cmd->add_option("--scene", o->scene,
                  "Scene directory: poses in its frame (poses.txt's), and its cameras for --time")
      ->check(CLI::ExistingDirectory);
  cmd->add_option("--time", o->time,
                  "Render the scene's view at this time (s) as training does (needs --scene)");
  cmd->add_option("--downscale", o->downscale,
                  "--time: divide image size and intrinsics by this (train's --downscale)")
      ->capture_default_str();
  cmd->add_option("--poses", o->poses, "--time: estimated (poses.txt) or truth (gt/poses.txt)")
      ->capture_default_str();
  cmd->add_option(
         "--pose-frame", o->pose_frame,
         "Frame of --pose/--camera: scene (poses.txt's; the default when the scene is known), original "
         "(original world), model (the PLY's coordinates; the default otherwise)")
      ->capture_default_str();
  cmd->add_option("--levels", o->levels,
                  "train's levels.json: apply the level of --time (interpolated between training frames)")
      ->check(CLI::ExistingFile);
  cmd->add_flag("--counts", o->counts,
                "With --levels and --bit-depth 16: write raw counts (the inverse of training's stretch)");
  cmd->callback([o] { run_render(*o); });
}

}  // namespace litgs::tools
