// refine: LiDAR-plane bundle adjustment of the poses (`litgs-engine refine`) on DIR/refine/scene, whose
// poses.txt becomes the refined trajectory (the input kept as poses_prior.txt) for train and eval.
#include <stdexcept>

#include "host/refine/refine_option_names.h"
#include "host/run/stage.h"

namespace litgs::host::run {
namespace {

namespace fs = std::filesystem;

// refine.absolute_priors as `refine --priors`: "auto" is absolute for a Metashape or COLMAP INPUT, else
// refine's own auto (the scene's poses_origin).
std::string priors(const StageContext& c) {
  const std::string& v = c.config.refine.absolute_priors;
  if (v == "true") return "absolute";
  if (v == "false") return "odometry";
  if (v != "auto")
    throw std::invalid_argument("refine.absolute_priors: expected auto, true or false, not '" + v + "'");
  return c.kind == InputKind::kMetashape || c.kind == InputKind::kColmap ? "absolute" : "auto";
}

StagePlan plan(const StageContext& c) {
  const RunConfig::Refine& o = c.config.refine;
  const fs::path scene = c.scene();
  StagePlan p;
  p.options = section_json(c.config, "refine");
  if (!o.enabled) {
    p.skip_reason = "refine.enabled is false";
  } else if (o.tracks == "oracle" && !fs::exists(scene / "gt" / "poses.txt")) {
    p.skip_reason = "refine.tracks is oracle and the scene has no gt/poses.txt to make them from";
  } else if (o.tracks != "oracle" && !fs::is_directory(scene / "sfm")) {
    p.skip_reason = "refine.tracks is " + o.tracks + " and the scene has no sfm/ (match did not run)";
  }
  if (!p.skip_reason.empty()) return p;
  nlohmann::json flags_from = p.options;
  flags_from["priors"] = priors(c);
  if (o.planes && !fs::exists(scene / "lidar" / "map.pcd")) {
    flags_from["planes"] = false;
    p.notes.push_back("the scene has no LiDAR map: refine runs without the plane term");
  }
  plan_on_scene_copy(
      c, "refine", SceneCopy{scene, {"poses.txt", "poses_prior.txt"}, {"refine", "refine.json"}},
      option_flags(flags_from, {refine_option::kTracks, refine_option::kAnchors, refine_option::kPlanes,
                                refine_option::kScans, refine_option::kRounds, refine_option::kThreads,
                                refine_option::kPriors}),
      o.extra_args, p);
  return p;
}

nlohmann::json result(const StageContext& c) {
  const fs::path scene = c.stage_dir("refine") / "scene";
  const nlohmann::json r = read_stage_json(scene / "refine.json");
  nlohmann::json metrics = pick(r, {"status", "outcome", "tracks", "frames", "points", "ate_before_m",
                                    "ate_after_m", "ate_rejected_m", "seconds"});
  if (r.contains("holdout") && r["holdout"].value("measured", false))
    metrics["holdout_median_px"] = {r["holdout"]["prior_median_px"], r["holdout"]["refined_median_px"]};
  metrics["reprojection_rms_px"] = {r["before"]["reprojection_rms_px"], r["after"]["reprojection_rms_px"]};
  // Only where points were held to LiDAR planes (a scene without LiDAR has no plane residual, not a 0).
  if (r["before"].value("plane_points", 0) > 0 || r["after"].value("plane_points", 0) > 0)
    metrics["plane_rms_m"] = {r["before"]["plane_rms_m"], r["after"]["plane_rms_m"]};
  // The scans' point-to-plane RMS at the first round's association and after the last solve.
  const nlohmann::json& rounds = r.value("rounds", nlohmann::json::array());
  if (!rounds.empty() && rounds.front().contains("scans") && rounds.front()["scans"].value("links", 0) > 0)
    metrics["scan_rms_m"] = {rounds.front()["scans"]["rms_before_m"], rounds.back()["scans"]["rms_after_m"]};
  return {{"scene", scene.string()}, {"metrics", metrics}};
}

}  // namespace

Stage refine_stage() {
  return {"refine", "poses refined by LiDAR-plane bundle adjustment", plan, result};
}

}  // namespace litgs::host::run
