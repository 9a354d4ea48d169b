// The differentiable Gaussian rasterizer on the device: projection, depth sort, tile binning (a stable
// tile sort of depth-ordered intersections), forward alpha blending, and backward to every parameter.
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include "engine/buffer.h"
#include "engine/context.h"
#include "engine/kernel.h"
#include "engine/sequence.h"
#include "kernels/sort/radix_sort.h"
#include "kernels/splat/splat_shared.h"
#include "kernels/splat/splat_types.h"

namespace litgs::kernels {

struct RasterizerOptions {
  // Bit-identical gradients run to run: per-intersection gradient rows summed in a fixed order, instead of
  // float atomics. Slower; for tests and reproducible runs.
  bool deterministic = false;
  // Use the compare-and-swap fallback even where VK_EXT_shader_atomic_float exists (tests both paths).
  bool force_cas_atomics = false;
  // false: the gradients of the expected depth and of the alpha map move Gaussians (mean, scale, rotation,
  // through the depth and the footprint) but do not reach their opacity, which only the image decides.
  // Training with the LiDAR term uses it: through opacity the depth loss can reweight which Gaussians are
  // seen instead of moving them, and that trades against the image (README, Training). true: the exact
  // gradient.
  bool depth_gradient_to_opacity = true;
};

// A Gaussian model on the device, one buffer per attribute (structure of arrays, each binding bounded).
// The arrays may hold more rows than `count` (a training model's spare capacity); kernels use `count`.
struct DeviceGaussians {
  DeviceGaussians(engine::Context& context, const GaussianModel& model);
  // Uninitialized arrays of `capacity` rows (at least 1), `count` of them in use.
  DeviceGaussians(engine::Context& context, uint32_t channels, uint32_t sh_degree, size_t count,
                  size_t capacity);
  void upload(const GaussianModel& model);  // same size, channels and degree
  GaussianModel download() const;           // the first `count` rows
  size_t size() const { return count; }
  size_t capacity() const { return opacity_logits.size(); }

  size_t count;
  uint32_t channels, sh_degree;
  engine::DeviceArray<float> means;           // [N][3]
  engine::DeviceArray<float> log_scales;      // [N][3]
  engine::DeviceArray<float> quats;           // [N][4]
  engine::DeviceArray<float> opacity_logits;  // [N]
  engine::DeviceArray<float> sh;              // [N][K][C]
};

// The push constants of the splat kernels for `camera` and `count` elements (also used by kernels outside the
// rasterizer that project Gaussians, e.g. the densification statistics).
SplatView make_splat_view(const SplatCamera& camera, uint32_t count, uint32_t sh_coeffs);

class Rasterizer {
 public:
  Rasterizer(engine::Context& context, uint32_t channels, RasterizerOptions options = {});
  ~Rasterizer();

  // Renders the model from the camera: two submits, with one 8-byte readback (the intersection count)
  // between them. Outputs stay on the device until downloaded.
  void forward(const DeviceGaussians& gaussians, const SplatCamera& camera);
  RenderImages<float> download_images();

  // Gradients of sum(grad . outputs) of the last forward, for the same Gaussians (one submit).
  void backward(const RenderGradInput& grad);
  GaussianGrads<float> download_grads() const;

  // Device-side use inside a training step (no host round trip): the last forward's outputs, the upstream
  // gradient buffers to fill, and the parameter gradients the backward writes. Sizes: outputs and upstream
  // gradients hold at least C*H*W (image) or H*W values; parameter gradients at least N rows.
  struct DeviceOutputs {
    const engine::Buffer* image;   // [C][H][W]
    const engine::Buffer* depth;   // [H][W]
    const engine::Buffer* alpha;   // [H][W]
    const engine::Buffer* rects;   // [N][4] uint tile rectangles; empty (x1 <= x0) when culled
    // [4] uint, the last forward's counters (splat_shared.h): [0] Gaussians culled as non-finite by the
    // projection, [1] tiles whose intersection list the forward truncated; [2], [3] unused.
    const engine::Buffer* counters;
  };
  DeviceOutputs device_outputs() const;
  struct DeviceUpstream {
    const engine::Buffer* image;  // [C][H][W] dL/dimage
    const engine::Buffer* depth;  // [H][W] dL/ddepth
    const engine::Buffer* alpha;  // [H][W] dL/dalpha
  };
  // Makes sure the upstream buffers exist for the last forward's size and returns them (zero-filled on
  // creation; the caller overwrites or fills them before record_backward).
  DeviceUpstream upstream_buffers();
  struct DeviceGrads {
    const engine::Buffer* means;           // [N][3]
    const engine::Buffer* log_scales;      // [N][3]
    const engine::Buffer* quats;           // [N][4]
    const engine::Buffer* opacity_logits;  // [N]
    const engine::Buffer* sh;              // [N][K][C]
    const engine::Buffer* means2d;         // [N][2]
  };
  // Records the backward from the upstream buffers into `sequence` (no submit), for a training step that
  // records loss kernels before it and the optimizer after it.
  DeviceGrads record_backward(engine::Sequence& sequence);

  // Per-kernel GPU times of the last forward (and backward, if run after it).
  const std::vector<engine::KernelTime>& profile() const { return profile_; }
  uint64_t intersections() const { return intersections_; }
  // Tiles whose intersection list the last forward truncated (counters[1] of rasterize_forward.comp; one small
  // download). 0 before any forward.
  uint64_t truncated_tile_lists() const;
  uint32_t channels() const { return channels_; }
  bool uses_float_atomics() const;

 private:
  struct Buffers;
  std::unique_ptr<engine::Kernel> make(const char* name, uint32_t bindings,
                                       std::vector<engine::SpecConstant> extra_constants = {});
  void append_profile(const engine::Sequence& sequence);

  engine::Context* context_;
  uint32_t channels_;
  RasterizerOptions options_;
  RadixSort sort_;
  ExclusiveScan scan_;
  std::unique_ptr<engine::Kernel> project_, gather_, emit_, ranges_, forward_, backward_, reduce_,
      project_backward_;
  std::unique_ptr<Buffers> buffers_;
  const DeviceGaussians* last_gaussians_ = nullptr;
  SplatCamera last_camera_;
  uint64_t intersections_ = 0;
  std::vector<engine::KernelTime> profile_;
};

}  // namespace litgs::kernels
