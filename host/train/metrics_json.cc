#include "host/train/metrics_json.h"

#include "io/atomic_file.h"

namespace litgs::host {

nlohmann::json metrics_json(const TrainReport& report, const TrainingData& data, const TrainOptions& o) {
  size_t heldout = 0;
  for (const auto& v : data.views) heldout += v.heldout;
  nlohmann::json metrics = {{"iterations", report.iterations},
                            {"wall_s", report.wall_s},
                            {"ms_per_iteration", report.ms_per_iteration},
                            {"gaussians", report.gaussians},
                            {"peak_device_bytes", report.peak_device_bytes},
                            {"heldout_psnr", report.final_eval.psnr_db},
                            {"heldout_ssim", report.final_eval.ssim},
                            {"heldout_views", heldout},
                            {"training_views", data.views.size() - heldout},
                            {"width", data.width},
                            {"height", data.height},
                            {"lambda_geo", o.lambda_geo},
                            {"nonfinite_pruned", report.nonfinite_pruned},
                            {"plane_pruned", report.plane_pruned},
                            {"evaluations", nlohmann::json::array()},
                            {"kernel_ms_per_iteration", nlohmann::json::object()}};
  for (const auto& [name, ms] : report.kernel_ms_per_iteration) metrics["kernel_ms_per_iteration"][name] = ms;
  metrics["heldout_psnr_per_view"] = nlohmann::json::array();
  for (const auto& [name, psnr] : report.final_eval.view_psnr_db)
    metrics["heldout_psnr_per_view"].push_back({{"view", name}, {"psnr_db", psnr}});
  // Where peak_device_bytes went, by buffer name (engine::Buffer::peak_breakdown), most first.
  metrics["peak_device_breakdown"] = nlohmann::json::array();
  for (const auto& [name, bytes] : report.peak_device_breakdown)
    metrics["peak_device_breakdown"].push_back({{"buffer", name}, {"bytes", bytes}});
  // Held-out error in the raw frames' counts (the stretch window's units); with a level model, heldout_psnr,
  // heldout_ssim and heldout_mae_counts score each held-out render at the level interpolated from the
  // training frames around it in time, and the *_identity_level fields score it at the identity level.
  metrics["level_model"] = o.level_model;
  if (report.final_eval.mae_counts >= 0) metrics["heldout_mae_counts"] = report.final_eval.mae_counts;
  if (report.final_eval.leveled) {
    metrics["heldout_psnr_identity_level"] = report.final_eval.psnr_identity_db;
    metrics["heldout_mae_counts_identity_level"] = report.final_eval.mae_counts_identity;
    metrics["level_nonfinite_skips"] = report.level_nonfinite_skips;
  }
  metrics["stretch_counts"] = {data.stretch_low, data.stretch_high};
  if (report.final_eval.depth_plane_rmse_m >= 0)
    metrics["heldout_depth_plane_rmse_m"] = report.final_eval.depth_plane_rmse_m;
  for (const auto& e : report.evals) metrics["evaluations"].push_back(to_json(e));
  // Over the whole run (a resumed run continues its checkpoint's); always present, 0 when nothing happened.
  metrics["counters"] = to_json(report.counters);
  metrics["resumes"] = nlohmann::json::array();
  for (const auto& r : report.resumes) metrics["resumes"].push_back(to_json(r));
  // `--max-gaussians grow`: each phase's budget, size, validation score and decision, and why it stopped.
  if (!report.growth.is_null()) metrics["budget_growth"] = report.growth;
  // wall_s, ms_per_iteration and kernel_ms_per_iteration are of this call: iterations
  // start_iteration..iterations.
  metrics["start_iteration"] = report.start_iteration;
  metrics["point_cloud_frame"] = o.recentred_output ? "recentred" : "original";
  metrics["scene_world_offset_m"] = {data.world_offset_m.x(), data.world_offset_m.y(),
                                     data.world_offset_m.z()};
  return metrics;
}

void write_metrics_json(const std::filesystem::path& path, const TrainReport& report,
                        const TrainingData& data, const TrainOptions& options) {
  const nlohmann::json metrics = metrics_json(report, data, options);
  io::write_file_atomic(path, [&](std::ostream& out) { out << metrics.dump(2) << "\n"; });
}

}  // namespace litgs::host
