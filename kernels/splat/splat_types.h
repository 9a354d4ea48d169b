// Host-side types of the rasterizer: the Gaussian model (structure of arrays), the camera, and the
// outputs and gradients of a render. Shapes are written beside every array.
#pragma once

#include <cstdint>
#include <glm/glm.hpp>
#include <string>
#include <vector>

namespace litgs::kernels {

// A Gaussian model on the host. Raw parameters, as the standard 3DGS PLY stores them.
struct GaussianModel {
  uint32_t channels = 1;              // C: 1 for thermal, 3 for RGB
  uint32_t sh_degree = 3;             // the model's degree; K = (sh_degree + 1)^2 coefficients per channel
  std::vector<float> means;           // [N][3] world, metres
  std::vector<float> log_scales;      // [N][3]
  std::vector<float> quats;           // [N][4] w x y z, unnormalized
  std::vector<float> opacity_logits;  // [N]
  std::vector<float> sh;              // [N][K][C]: coefficient-major, channel inner

  uint32_t sh_coeffs() const { return (sh_degree + 1) * (sh_degree + 1); }
  size_t size() const { return opacity_logits.size(); }
  void resize(size_t n);
  // Throws std::invalid_argument naming the array whose size disagrees with N, or a bad channel/degree.
  void check() const;
};

// A pinhole view: world-to-camera pose, intrinsics in pixels, image size.
struct SplatCamera {
  glm::dmat3 R_cam_world{1.0};  // p_cam = R_cam_world p_world + t_cam_world
  glm::dvec3 t_cam_world{0.0};
  double fx = 0, fy = 0, cx = 0, cy = 0;  // pixel (i, j) has its centre at (i + 0.5, j + 0.5)
  uint32_t width = 0, height = 0;
  double near_m = 0.01;    // Gaussians nearer than this are culled
  uint32_t sh_degree = 3;  // active SH degree, at most the model's
  // Throws std::invalid_argument naming the bad field.
  void check() const;
};

// Per-pixel outputs of a render, T = float (device) or double (reference).
template <class T>
struct RenderImages {
  uint32_t width = 0, height = 0, channels = 0;
  std::vector<T> image;           // [C][H][W]
  std::vector<T> depth;           // [H][W] expected depth sum(w z) / sum(w), 0 where sum(w) < 1e-6
  std::vector<T> alpha;           // [H][W] accumulated alpha = 1 - final transmittance
  std::vector<uint32_t> last;     // [H][W] entries of the pixel's tile list walked (for backward)
  uint32_t culled_nonfinite = 0;  // Gaussians with a non-finite parameter (culled, counted)
  uint64_t intersections = 0;     // (Gaussian, tile) pairs
  uint32_t walks_cut_short = 0;   // subgroup walks a driver's loop limit ended early (device; 0 expected)
};

// Upstream gradients of a render's outputs.
struct RenderGradInput {
  std::vector<float> image;  // [C][H][W]
  std::vector<float> depth;  // [H][W] (may be empty: zero)
  std::vector<float> alpha;  // [H][W] (may be empty: zero)
};

// Gradients w.r.t. every parameter of the model, plus the screen-space mean gradient.
template <class T>
struct GaussianGrads {
  std::vector<T> means;           // [N][3]
  std::vector<T> log_scales;      // [N][3]
  std::vector<T> quats;           // [N][4]
  std::vector<T> opacity_logits;  // [N]
  std::vector<T> sh;              // [N][K][C]
  std::vector<T> means2d;         // [N][2] dL/d(pixel position), for densification
};

}  // namespace litgs::kernels
