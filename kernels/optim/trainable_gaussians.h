// A Gaussian model being trained on the device: its parameters (a DeviceGaussians the rasterizer renders),
// the Adam moments of every parameter group, and the densification statistics; the Adam step, the
// statistics, adaptive density control (clone, split, prune, stream compaction) and the opacity reset.
//
// A training step records, into one sequence: the loss and Rasterizer::record_backward, then
// record_accumulate_stats (it reads the parameters the forward used), then record_adam_step.
// densify_and_prune runs its own two submits with one small readback, and replaces the DeviceGaussians
// (its buffers are double-buffered with geometric capacity): call Rasterizer::forward again after it.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <vector>

#include "engine/buffer.h"
#include "engine/context.h"
#include "engine/sequence.h"
#include "kernels/densify/densify.h"
#include "kernels/optim/adam.h"
#include "kernels/optim/gaussian_adam.h"
#include "kernels/optim/training_state.h"
#include "kernels/scan/scan.h"
#include "kernels/splat/rasterizer.h"

namespace litgs::kernels {

class TrainableGaussians {
 public:
  // densify_statistics false: no grad_accum / denom / max_radius arrays (12 bytes per Gaussian), for
  // strategies that do not read them (MCMC); record_accumulate_stats and densify_and_prune then throw
  // std::logic_error, and download_state() reports them as zeros.
  TrainableGaussians(engine::Context& context, const GaussianModel& model, AdamOptions adam = {},
                     bool densify_statistics = true);
  TrainableGaussians(engine::Context& context, const TrainingState& state, AdamOptions adam = {},
                     bool densify_statistics = true);
  ~TrainableGaussians();
  TrainableGaussians(const TrainableGaussians&) = delete;
  TrainableGaussians& operator=(const TrainableGaussians&) = delete;

  // The parameters, for Rasterizer::forward. Replaced (another object) by densify_and_prune.
  const DeviceGaussians& gaussians() const;
  size_t size() const;
  size_t capacity() const;  // rows the current buffers hold

  // What the fused step needs when the rasterizer stored no parameter gradients
  // (RasterizerOptions::parameter_gradients false): the forward's tile rectangles and camera, and the
  // regularizers' weights (kernels/optim/gaussian_adam.h).
  struct FusedStep {
    const engine::Buffer* tile_rects = nullptr;
    SplatCamera camera;
    RegularizationWeights regularization;
  };
  // Records one Adam step (step counts from 1) of every group from the rasterizer's gradients: from the
  // stored gradients of every group (grads.means ... grads.sh), or, when the rasterizer stored none, in one
  // fused pass from grads.grad2d, which needs `fused` (std::invalid_argument otherwise).
  void record_adam_step(engine::Sequence& sequence, const Rasterizer::DeviceGrads& grads,
                        const LearningRates& lr, uint32_t step, const FusedStep* fused = nullptr);
  // Records the densification statistics of the last backward: for Gaussians whose tile rectangle (the
  // rasterizer's `rects`) is not empty, grad_accum += |(dL/du W/2, dL/dv H/2)|, denom += 1, and
  // max_radius = max(max_radius, opacity-aware screen radius in pixels). Record before the Adam step.
  void record_accumulate_stats(engine::Sequence& sequence, const Rasterizer::DeviceGrads& grads,
                               const engine::Buffer& rects, const SplatCamera& camera);
  // Clones, splits and prunes on the device (two submits, one readback of 48 bytes: the report and the new
  // count). `plane_distance` ([N] float metres, optional) enables the plane prune of the options.
  DensifyReport densify_and_prune(const DensifyOptions& options, float scene_extent, uint32_t step,
                                  const engine::Buffer* plane_distance = nullptr);
  // Records opacity = min(opacity, reset_opacity) and zeroes the opacity moments (3DGS reset_opacity).
  void record_reset_opacity(engine::Sequence& sequence, float reset_opacity = 0.01f);

  // Every per-row array (parameters, Adam moments, densification statistics) with its 32-bit words per
  // row, for strategies that move rows themselves (kernels/mcmc/).
  struct RowArray {
    enum Kind { kParameter, kMoment, kStatistic };
    const engine::Buffer* buffer;
    uint32_t stride;
    Kind kind;
  };
  std::vector<RowArray> row_arrays() const;
  // Sets the row count to `rows` (>= size()); new rows are zero. Grows the buffers (keeping the rows) by
  // at least 1.5x when they are too small, to at most `capacity_cap` rows (0: no cap) or `rows` if more.
  void grow_rows(size_t rows, size_t capacity_cap);

  GaussianModel download() const;
  TrainingState download_state() const;
  // Replaces parameters, moments and statistics (any size; the same channels and SH degree): a resume, or a
  // caller's own statistics. Call Rasterizer::forward again after it.
  void load_state(const TrainingState& state);
  // Elements skipped by Adam since construction because their gradient or update was not finite, per group.
  std::array<uint32_t, kParamGroupCount> nonfinite_grad_counts() const;
  const AdamOptions& adam_options() const { return adam_options_; }

 private:
  struct Slot;
  void upload_state(Slot& slot, const TrainingState& state);
  void ensure_capacity(Slot& slot, size_t rows);
  void require_statistics(const char* what) const;
  uint32_t sh_values() const;

  engine::Context* context_;
  AdamOptions adam_options_;
  bool statistics_;  // the densification statistics are kept
  uint32_t channels_, sh_degree_;
  AdamKernel adam_;
  GaussianAdamKernel gaussian_adam_;
  ExclusiveScan scan_;
  std::unique_ptr<engine::Kernel> stats_, candidates_, decide_, scatter_rows_, scatter_geometry_,
      reset_opacity_;
  std::unique_ptr<Slot> current_, spare_;
  std::unique_ptr<engine::DeviceArray<uint32_t>> adam_counters_;  // [ADAM_COUNTER_SLOTS]
  // Densification scratch, [N] each, grown geometrically.
  std::unique_ptr<engine::DeviceArray<uint32_t>> candidate_, rank_, decision_, counts_, offsets_, report_;
  std::unique_ptr<engine::DeviceArray<float>> no_plane_;  // bound when no plane distances are given
};

}  // namespace litgs::kernels
