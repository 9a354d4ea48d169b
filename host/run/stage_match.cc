// match: the thermal front end (`litgs-engine match`) on DIR/match/scene, which gets a fresh sfm/.
#include "host/frontend/match_option_names.h"
#include "host/run/stage.h"

namespace litgs::host::run {
namespace {

namespace fs = std::filesystem;

StagePlan plan(const StageContext& c) {
  const RunConfig::Match& o = c.config.match;
  const fs::path scene = c.scene();
  StagePlan p;
  p.options = section_json(c.config, "match");
  if (!o.enabled) {
    p.skip_reason = "match.enabled is false";
    return p;
  }
  plan_on_scene_copy(
      c, "match", SceneCopy{scene, {}, {"sfm"}},
      option_flags(p.options, {match_option::kFeatures, match_option::kMatcher, match_option::kClahe,
                               match_option::kPairs, match_option::kMaxKeypoints, match_option::kXfeatScale,
                               match_option::kThreads}),
      o.extra_args, p);
  return p;
}

nlohmann::json result(const StageContext& c) {
  const fs::path scene = c.stage_dir("match") / "scene";
  const nlohmann::json summary = read_stage_json(scene / "sfm" / "frontend.json").at("summary");
  return {
      {"scene", scene.string()},
      {"metrics", pick(summary, {"keypoints_per_image", "inlier_ratio", "pairs_tried", "pairs_verified",
                                 "tracks", "points", "mean_track_length", "mean_reprojection_error_px"})}};
}

}  // namespace

Stage match_stage() {
  return {"match", "thermal front end: contrast, features, verified matches, tracks", plan, result};
}

}  // namespace litgs::host::run
