// `litgs-engine render`: one view of a 3DGS PLY model, on the device (or with the double-precision CPU
// reference), to PNG: the image, and optionally expected depth and accumulated alpha.
#include <CLI/CLI.hpp>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <stdexcept>

#include "engine/context.h"
#include "io/gaussian_ply.h"
#include "io/image.h"
#include "kernels/splat/rasterizer.h"
#include "kernels/splat/reference.h"
#include "tools/commands.h"

namespace litgs::tools {
namespace {

struct RenderOptions {
  std::string model;                 // 3DGS PLY
  std::string camera_json;           // camera file (see camera_from_json), or the flags below
  std::vector<double> pose;          // qw qx qy qz tx ty tz: world-to-camera, COLMAP's images.txt order
  std::vector<double> intrinsics;    // fx fy cx cy in pixels
  uint32_t width = 0, height = 0;
  int sh_degree = -1;                // -1: the model's degree
  std::string out;                   // image PNG: 8-bit, or 16-bit with --bit-depth 16; values clamped to [0, 1]
  int bit_depth = 8;
  std::string depth_out;             // expected depth, 16-bit PNG in units of 1/depth_scale metres
  double depth_scale = 1000.0;       // depth PNG value per metre (1000: millimetres, up to 65.535 m)
  std::string alpha_out;             // accumulated alpha, 8-bit PNG
  bool reference = false;            // render with the double-precision CPU reference instead of the device
};

glm::dmat3 rotation_from_quat(double w, double x, double y, double z) {
  const double n = std::sqrt(w * w + x * x + y * y + z * z);
  if (!(n > 1e-12) || !std::isfinite(n)) throw std::invalid_argument("camera rotation quaternion is zero or not finite");
  w /= n, x /= n, y /= n, z /= n;
  return glm::dmat3(1 - 2 * (y * y + z * z), 2 * (x * y + w * z), 2 * (x * z - w * y),  //
                    2 * (x * y - w * z), 1 - 2 * (x * x + z * z), 2 * (y * z + w * x),  //
                    2 * (x * z + w * y), 2 * (y * z - w * x), 1 - 2 * (x * x + y * y));
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
    if (q.size() != 4 || t.size() != 3) throw std::invalid_argument("q_cam_world needs 4 values, t_cam_world 3");
    c.R_cam_world = rotation_from_quat(q[0], q[1], q[2], q[3]);
    c.t_cam_world = {t[0], t[1], t[2]};
    return c;
  } catch (const std::exception& e) {
    throw std::runtime_error(path + ": bad camera file: " + e.what());
  }
}

io::Image to_image(const std::vector<float>& planes, uint32_t w, uint32_t h, uint32_t channels, int bit_depth,
                   double scale) {
  io::Image img;
  img.width = static_cast<int>(w);
  img.height = static_cast<int>(h);
  img.channels = static_cast<int>(channels);
  img.bit_depth = bit_depth;
  img.data.resize(size_t{w} * h * channels);
  const double max_value = bit_depth == 16 ? 65535.0 : 255.0;
  for (uint32_t c = 0; c < channels; ++c)
    for (size_t p = 0; p < size_t{w} * h; ++p) {
      const double v = planes[c * size_t{w} * h + p] * scale;
      img.data[p * channels + c] =
          static_cast<uint16_t>(std::lround(std::clamp(std::isfinite(v) ? v : 0.0, 0.0, max_value)));
    }
  return img;
}

void run_render(const RenderOptions& o) {
  kernels::SplatCamera camera;
  if (!o.camera_json.empty()) {
    camera = camera_from_json(o.camera_json);
  } else {
    if (o.pose.size() != 7 || o.intrinsics.size() != 4 || o.width == 0 || o.height == 0)
      throw std::invalid_argument("give --camera FILE, or --pose (7 values) --intrinsics (4) --width --height");
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
  const kernels::GaussianModel model = io::read_gaussian_ply(o.model);
  camera.sh_degree = o.sh_degree < 0 ? model.sh_degree : static_cast<uint32_t>(o.sh_degree);
  camera.check();

  std::vector<float> image, depth, alpha;
  uint64_t intersections = 0;
  if (o.reference) {
    const auto r = kernels::reference_forward(model, camera);
    image.assign(r.image.begin(), r.image.end());
    depth.assign(r.depth.begin(), r.depth.end());
    alpha.assign(r.alpha.begin(), r.alpha.end());
    intersections = r.intersections;
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
  }
  const double full = o.bit_depth == 16 ? 65535.0 : 255.0;
  io::write_image(o.out, to_image(image, camera.width, camera.height, model.channels, o.bit_depth, full));
  if (!o.depth_out.empty())
    io::write_image(o.depth_out, to_image(depth, camera.width, camera.height, 1, 16, o.depth_scale));
  if (!o.alpha_out.empty()) io::write_image(o.alpha_out, to_image(alpha, camera.width, camera.height, 1, 8, 255.0));
  std::cout << "render: " << model.size() << " Gaussians, " << intersections << " tile intersections, "
            << camera.width << "x" << camera.height << (o.reference ? " (CPU reference)" : "") << " -> " << o.out
            << "\n";
}

}  // namespace

void add_render_command(CLI::App& app) {
  auto o = std::make_shared<RenderOptions>();
  CLI::App* cmd = app.add_subcommand("render", "Render one view of a 3DGS PLY model to PNG");
  cmd->add_option("--model", o->model, "3DGS PLY model")->required()->check(CLI::ExistingFile);
  cmd->add_option("--camera", o->camera_json, "Camera JSON: width height fx fy cx cy q_cam_world t_cam_world")
      ->check(CLI::ExistingFile);
  cmd->add_option("--pose", o->pose, "qw qx qy qz tx ty tz, world-to-camera (COLMAP images.txt order)")->expected(7);
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
  cmd->callback([o] { run_render(*o); });
}

}  // namespace litgs::tools
