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
  // seen instead of moving them, and that trades against the image (docs/experiments.md). true: the exact
  // gradient.
  bool depth_gradient_to_opacity = true;
  // List entries one rasterize pass walks per tile (kernels/splat/splat_shared.h); 0: derived per kernel from
  // the device's subgroup size so that no pass exceeds a driver's loop limit (the default). Tests set it to
  // force many passes on short lists, or one oversized pass.
  uint32_t entries_per_pass = 0;
  // false: the backward stops at the per-Gaussian rows (grad2d) and stores no parameter gradient
  // (DeviceGrads has only grad2d; download_grads() throws); the optimizer's fused step computes them
  // (kernels/optim/gaussian_adam.h). Training uses it: 108 B per Gaussian at SH degree 3 and one channel.
  bool parameter_gradients = true;
  // Pixels each rasterize invocation blends: 8 (a 2x4 block, 8x4 invocations per tile) or 1 (16x16
  // invocations); 0: 8 on a CPU device, where every subgroup reads its tile's whole list and eight pixels
  // share each read (the block roughly halves the rasterize time on lavapipe), 1 on a GPU, whose many lanes
  // want the 256 invocations (there the block roughly doubles it; figures: docs/performance.md, issue 18).
  // Tests set it to run both layouts on one device.
  uint32_t pixels_per_invocation = 0;
};

// Counters of a rasterizer's renders (Rasterizer::read_counters).
struct RasterizerCounters {
  uint32_t culled_nonfinite = 0;   // Gaussians culled for a non-finite parameter, last forward
  uint32_t longest_tile_list = 0;  // entries in the longest tile list, last forward
  uint32_t forward_passes = 0;     // rasterize passes of the last forward
  uint32_t backward_passes = 0;    // ... and of the last backward
  uint64_t walks_cut_short = 0;    // subgroup walks that a driver's loop limit ended early, all renders so
                                   // far (forward + backward); 0 unless a pass size is wrong for the device
  uint32_t contributions = 0;      // (pixel, Gaussian) pairs the last forward blended (and its backward
                                   // walks again): SPLAT_COUNTER_CONTRIBUTIONS
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
    const engine::Buffer* image;  // [C][H][W]
    const engine::Buffer* depth;  // [H][W]
    const engine::Buffer* alpha;  // [H][W]
    // [N][2] uint tile rectangles, packed (splat/tile_rect.glsl); empty (x1 <= x0) when culled
    const engine::Buffer* rects;
    // [SPLAT_COUNTER_COUNT] uint (splat_shared.h, SPLAT_COUNTER_*): the last forward's culls, and the running
    // totals of walks cut short, for a copy inside a training step's submit.
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
    // Null without RasterizerOptions::parameter_gradients.
    const engine::Buffer* means;           // [N][3]
    const engine::Buffer* log_scales;      // [N][3]
    const engine::Buffer* quats;           // [N][4]
    const engine::Buffer* opacity_logits;  // [N]
    const engine::Buffer* sh;              // [N][K][C]
    // [N][SPLAT_GRAD2D_FIXED + C] the projected quantities' gradients; dL/d(mean2d) in columns 0 and 1
    // (densification statistics read them there: no separate copy).
    const engine::Buffer* grad2d;
  };
  // Records the backward from the upstream buffers into `sequence` (no submit), for a training step that
  // records loss kernels before it and the optimizer after it.
  DeviceGrads record_backward(engine::Sequence& sequence);

  // The counters (one small readback: call it when reporting, not every step).
  RasterizerCounters read_counters() const;
  // List entries per pass of the forward and of the backward on this device (see RasterizerOptions).
  uint32_t forward_entries_per_pass() const { return forward_entries_per_pass_; }
  // Pixels per rasterize invocation on this device (RasterizerOptions::pixels_per_invocation resolved).
  uint32_t pixels_per_invocation() const { return pixels_per_invocation_; }
  uint32_t backward_entries_per_pass() const { return backward_entries_per_pass_; }

  // Per-kernel GPU times of the last forward (and backward, if run after it).
  const std::vector<engine::KernelTime>& profile() const { return profile_; }
  uint64_t intersections() const { return intersections_; }
  uint32_t channels() const { return channels_; }
  bool uses_float_atomics() const;

 private:
  struct Buffers;
  std::unique_ptr<engine::Kernel> make(const char* name, uint32_t bindings, uint32_t push_constant_bytes,
                                       std::vector<engine::SpecConstant> extra_constants = {},
                                       std::vector<engine::TexelBinding> texel_bindings = {});
  uint32_t passes_for(uint32_t entries_per_pass) const;
  void append_profile(const engine::Sequence& sequence);

  engine::Context* context_;
  uint32_t channels_;
  RasterizerOptions options_;
  RadixSort sort_;
  ExclusiveScan scan_;
  std::unique_ptr<engine::Kernel> project_, gather_, lengths_, emit_, ranges_, forward_, backward_, reduce_,
      project_backward_;
  std::unique_ptr<Buffers> buffers_;
  const DeviceGaussians* last_gaussians_ = nullptr;
  SplatCamera last_camera_;
  uint64_t intersections_ = 0;
  uint32_t longest_tile_list_ = 0, forward_passes_ = 0, backward_passes_ = 0;
  uint32_t forward_entries_per_pass_ = 0, backward_entries_per_pass_ = 0;
  uint32_t pixels_per_invocation_ = 8;
  uint32_t forward_walks_cut_before_ = 0;  // the running counter before the last forward's passes
  std::vector<engine::KernelTime> profile_;
};

}  // namespace litgs::kernels
