#include "tools/render_view.h"

#include <algorithm>
#include <cmath>
#include <iostream>
#include <sstream>
#include <stdexcept>

#include "host/train/output_frame.h"
#include "io/gaussian_ply.h"

namespace litgs::tools {

glm::dmat3 rotation_from_quat(double w, double x, double y, double z) {
  const double n = std::sqrt(w * w + x * x + y * y + z * z);
  if (!(n > 1e-12) || !std::isfinite(n))
    throw std::invalid_argument("camera rotation quaternion is zero or not finite");
  w /= n, x /= n, y /= n, z /= n;
  return glm::dmat3(1 - 2 * (y * y + z * z), 2 * (x * y + w * z), 2 * (x * z - w * y),  //
                    2 * (x * y - w * z), 1 - 2 * (x * x + z * z), 2 * (y * z + w * x),  //
                    2 * (x * z + w * y), 2 * (y * z - w * x), 1 - 2 * (x * x + y * y));
}

std::string vector_text(const Eigen::Vector3d& v) {
  std::ostringstream s;
  s << "[" << v.x() << ", " << v.y() << ", " << v.z() << "]";
  return s.str();
}

FramedModel load_framed_model(const std::filesystem::path& ply, const std::string& pose_frame,
                              const std::optional<Eigen::Vector3d>& scene_offset_given,
                              const std::string& scene_name) {
  if (pose_frame != "auto" && pose_frame != "scene" && pose_frame != "original" && pose_frame != "model")
    throw std::invalid_argument("--pose-frame must be auto, scene, original or model, not '" + pose_frame +
                                "'");
  FramedModel out;
  out.model = io::read_gaussian_ply(ply);
  const host::ModelFrame model_frame = host::read_model_frame(ply);
  std::optional<Eigen::Vector3d> scene_offset = model_frame.scene_world_offset_m;
  if (scene_offset_given) {
    if (scene_offset && *scene_offset != *scene_offset_given)
      std::cerr << "note: " << ply.string() << " was trained on a scene with world_offset_m "
                << vector_text(*scene_offset) << "; poses are taken in " << scene_name
                << "'s frame (world_offset_m " << vector_text(*scene_offset_given) << ")\n";
    scene_offset = scene_offset_given;
  }
  out.frame = pose_frame == "auto" ? (scene_offset ? "scene" : "model") : pose_frame;
  if (out.frame == "scene") {
    if (!scene_offset)
      throw std::invalid_argument(ply.string() +
                                  " does not state the scene it was trained on (no "
                                  "litgs_scene_world_offset_m header line): give --scene DIR for "
                                  "--pose-frame scene");
    out.frame_offset = *scene_offset;
  } else if (out.frame == "model") {
    out.frame_offset = model_frame.world_offset_m;
  }
  out.model = host::shift_means(std::move(out.model), model_frame.world_offset_m - out.frame_offset);
  return out;
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

}  // namespace litgs::tools
