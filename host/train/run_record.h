// What a training run reports and carries across a resume besides the model: its evaluations, its counters of
// silent events (non-finite skips and culls, walks a driver cut short, prunes), and where it was resumed.
// Header only and free of Vulkan, so that the checkpoint reader (and its fuzz target) can parse it.
#pragma once

#include <array>
#include <cstdint>
#include <limits>
#include <nlohmann/json.hpp>
#include <string>
#include <utility>
#include <vector>

#include "kernels/optim/training_state.h"

namespace litgs::host {

struct EvalResult {
  uint32_t iteration = 0;
  double psnr_db = 0;  // mean over held-out views
  double ssim = 0;
  double depth_plane_rmse_m = -1;  // against ground-truth planes where the scene has them; -1 otherwise
  // Mean |render - target| in the raw frames' counts (the stretch window's units) of the image psnr_db
  // scores; -1 when not measured.
  double mae_counts = -1;
  // With a level model, psnr_db and mae_counts score the render at the held-out view's interpolated level;
  // these score it at the identity level (the map as it is).
  bool leveled = false;
  double psnr_identity_db = 0, mae_counts_identity = -1;
  // Each held-out view's PSNR (the terms of psnr_db's mean), with its frame name: one badly observed view
  // can decide the mean. Written to metrics.json for the final evaluation only.
  std::vector<std::pair<std::string, double>> view_psnr_db;
};

// Events of a run that change what is learnt without stopping it, summed over every iteration of the run (a
// resumed run continues the sums of its checkpoint). All zero in a healthy run.
struct TrainingCounters {
  // Per parameter group (kernels::kParamGroupNames): elements whose gradient or updated value was not finite,
  // which Adam left unchanged (kernels/optim/adam.comp).
  std::array<uint64_t, kernels::kParamGroupCount> adam_nonfinite_skips{};
  // Over the training renders: Gaussians the projection culled for a non-finite parameter
  // (kernels/splat/project.comp); one Gaussian culled in k iterations counts k times.
  uint64_t culled_nonfinite = 0;
  // Over the training renders: tiles whose intersection list the forward pass cut short
  // (kernels/splat/rasterize_forward.comp): Gaussians behind the cut were not drawn there.
  uint64_t walks_cut_short = 0;
  // Refinement: Gaussians removed for a non-finite parameter, or for their distance to the LiDAR plane, and
  // densification candidates not densified because the model reached max_gaussians.
  uint64_t pruned_nonfinite = 0;
  uint64_t pruned_plane = 0;
  uint64_t densify_capped = 0;

  uint64_t adam_nonfinite_total() const {
    uint64_t s = 0;
    for (uint64_t v : adam_nonfinite_skips) s += v;
    return s;
  }
  // The counters that mean something went wrong (prunes and the cap are part of normal refinement).
  bool any_anomaly() const {
    return adam_nonfinite_total() > 0 || culled_nonfinite > 0 || walks_cut_short > 0;
  }
  bool operator==(const TrainingCounters&) const = default;
};

// One resume of a run: the checkpoint's iteration, and whether its options could be compared with the resumed
// run's (false for checkpoints written before options were stored: format 1).
struct ResumeRecord {
  uint32_t from_iteration = 0;
  bool options_checked = true;
  bool operator==(const ResumeRecord&) const = default;
};

// Everything a checkpoint holds besides the training state.
struct RunRecord {
  // The run's options and the identity of its training data (host/train/run_options.h), compared on resume.
  nlohmann::json options = nlohmann::json::object();
  TrainingCounters counters;
  std::vector<EvalResult> evaluations;  // in iteration order, up to the checkpoint
  std::vector<ResumeRecord> resumes;
  // `--max-gaussians grow`: the growth's state (host/train/budget_growth.h); null otherwise.
  nlohmann::json growth;
};

// JSON forms (metrics.json and the checkpoint's run record use the same).
inline nlohmann::json to_json(const EvalResult& e) {
  nlohmann::json j = {{"iteration", e.iteration}, {"psnr_db", e.psnr_db}, {"ssim", e.ssim}};
  if (e.depth_plane_rmse_m >= 0) j["depth_plane_rmse_m"] = e.depth_plane_rmse_m;
  if (e.mae_counts >= 0) j["mae_counts"] = e.mae_counts;
  if (e.leveled) {
    j["psnr_identity_level_db"] = e.psnr_identity_db;
    j["mae_counts_identity_level"] = e.mae_counts_identity;
  }
  return j;
}
// JSON has no NaN or infinity: nlohmann writes them as null, read back as NaN.
inline double number_or_nan(const nlohmann::json& j) {
  return j.is_null() ? std::numeric_limits<double>::quiet_NaN() : j.get<double>();
}
inline EvalResult eval_from_json(const nlohmann::json& j) {
  EvalResult e;
  e.iteration = j.at("iteration").get<uint32_t>();
  e.psnr_db = number_or_nan(j.at("psnr_db"));
  e.ssim = number_or_nan(j.at("ssim"));
  if (j.contains("depth_plane_rmse_m")) e.depth_plane_rmse_m = number_or_nan(j.at("depth_plane_rmse_m"));
  if (j.contains("mae_counts")) e.mae_counts = number_or_nan(j.at("mae_counts"));
  e.leveled = j.contains("psnr_identity_level_db");
  if (e.leveled) {
    e.psnr_identity_db = number_or_nan(j.at("psnr_identity_level_db"));
    e.mae_counts_identity = number_or_nan(j.at("mae_counts_identity_level"));
  }
  return e;
}

inline nlohmann::json to_json(const TrainingCounters& c) {
  nlohmann::json adam = nlohmann::json::object();
  for (uint32_t g = 0; g < kernels::kParamGroupCount; ++g)
    adam[kernels::kParamGroupNames[g]] = c.adam_nonfinite_skips[g];
  return {{"adam_nonfinite_skips", adam},         {"culled_nonfinite", c.culled_nonfinite},
          {"walks_cut_short", c.walks_cut_short}, {"pruned_nonfinite", c.pruned_nonfinite},
          {"pruned_plane", c.pruned_plane},       {"densify_capped", c.densify_capped}};
}
inline TrainingCounters counters_from_json(const nlohmann::json& j) {
  TrainingCounters c;
  const nlohmann::json& adam = j.at("adam_nonfinite_skips");
  for (uint32_t g = 0; g < kernels::kParamGroupCount; ++g)
    c.adam_nonfinite_skips[g] = adam.at(kernels::kParamGroupNames[g]).get<uint64_t>();
  c.culled_nonfinite = j.at("culled_nonfinite").get<uint64_t>();
  c.walks_cut_short = j.at("walks_cut_short").get<uint64_t>();
  c.pruned_nonfinite = j.at("pruned_nonfinite").get<uint64_t>();
  c.pruned_plane = j.at("pruned_plane").get<uint64_t>();
  c.densify_capped = j.at("densify_capped").get<uint64_t>();
  return c;
}

inline nlohmann::json to_json(const ResumeRecord& r) {
  return {{"from_iteration", r.from_iteration}, {"options_checked", r.options_checked}};
}
inline ResumeRecord resume_from_json(const nlohmann::json& j) {
  return {j.at("from_iteration").get<uint32_t>(), j.at("options_checked").get<bool>()};
}

inline nlohmann::json to_json(const RunRecord& r) {
  nlohmann::json j = {{"options", r.options},
                      {"counters", to_json(r.counters)},
                      {"evaluations", nlohmann::json::array()},
                      {"resumes", nlohmann::json::array()}};
  for (const auto& e : r.evaluations) j["evaluations"].push_back(to_json(e));
  for (const auto& e : r.resumes) j["resumes"].push_back(to_json(e));
  if (!r.growth.is_null()) j["growth"] = r.growth;
  return j;
}
// Throws nlohmann::json::exception on a missing key or a wrong type.
inline RunRecord run_record_from_json(const nlohmann::json& j) {
  RunRecord r;
  r.options = j.at("options");
  if (!r.options.is_object()) throw nlohmann::json::type_error::create(302, "options must be an object", &j);
  r.counters = counters_from_json(j.at("counters"));
  for (const auto& e : j.at("evaluations")) r.evaluations.push_back(eval_from_json(e));
  for (const auto& e : j.at("resumes")) r.resumes.push_back(resume_from_json(e));
  if (j.contains("growth")) r.growth = j.at("growth");
  return r;
}

}  // namespace litgs::host
