#include "host/train/run_options.h"

#include <Eigen/Core>
#include <charconv>
#include <cstdio>
#include <cstring>
#include <map>
#include <set>
#include <sstream>
#include <stdexcept>

#include "host/train/lidar_planes.h"

namespace litgs::host {
namespace {

using nlohmann::json;

// A float as the double of its shortest decimal form (the same float reads back; equal floats give equal
// values, different floats different ones).
double shortest(float f) {
  char buf[64];
  const auto r = std::to_chars(buf, buf + sizeof buf, f);
  return std::stod(std::string(buf, r.ptr));
}

// FNV-1a over bytes: a fingerprint of the training data (not a security hash).
struct Fnv1a {
  uint64_t h = 1469598103934665603ull;
  void bytes(const void* p, size_t n) {
    const auto* c = static_cast<const unsigned char*>(p);
    for (size_t i = 0; i < n; ++i) h = (h ^ c[i]) * 1099511628211ull;
  }
  template <class T>
  void value(const T& v) {
    bytes(&v, sizeof v);
  }
  std::string hex() const {
    char buf[17];
    std::snprintf(buf, sizeof buf, "%016llx", static_cast<unsigned long long>(h));
    return buf;
  }
};

const char* mapping_name(IntensityMapping m) {
  switch (m) {
    case IntensityMapping::kPercentile:
      return "percentile";
    case IntensityMapping::kLinear:
      return "linear";
    default:
      return "auto";
  }
}

// The CLI flag of a stored option, "" where the CLI has none.
std::string flag_of(const std::string& section, const std::string& key) {
  static const std::map<std::string, std::string> train = {
      {"iterations", "--iterations"},
      {"lambda_geo", "--lambda-geo"},
      {"lambda_ssim", "--lambda-ssim"},
      {"geo_robust_scale_m", "--geo-robust-scale"},
      {"geo_gradient_to_opacity", "--geo-no-opacity-gradient (given: false)"},
      {"sh_degree", "--sh-degree"},
      {"densify_from", "--densify-from"},
      {"densify_until", "--densify-until"},
      {"densify_every", "--densify-every"},
      {"opacity_reset_every", "--opacity-reset-every"},
      {"densify_grad_threshold", "--densify-grad-threshold"},
      {"plane_prune_k", "--plane-prune-k"},
      {"max_gaussians", "--max-gaussians"},
      {"strategy", "--strategy"},
      {"mcmc_growth", "--mcmc-growth"},
      {"mcmc_noise_lr", "--mcmc-noise-lr"},
      {"eval_every", "--eval-every"},
      {"checkpoint_every", "--checkpoint-every"},
      {"deterministic", "--deterministic"},
      {"seed", "--seed"},
      {"progress_every", "--progress-every"},
      {"recentred_output", "--recentred-output"},
      {"level_model", "--level-model"},
      {"level_lr_log_gain", "--level-lr-gain"},
      {"level_lr_offset", "--level-lr-offset"},
      {"level_lr_vignetting", "--level-lr-vignetting"},
      {"level_lambda_identity", "--level-lambda-identity"},
      {"level_lambda_smooth", "--level-lambda-smooth"}};
  static const std::map<std::string, std::string> data = {{"downscale", "--downscale"},
                                                          {"holdout_every", "--holdout-every"},
                                                          {"intensity", "--intensity"},
                                                          {"poses", "--poses"}};
  const auto& table = section == "train" ? train : data;
  const auto it = table.find(key);
  return it == table.end() ? "" : it->second;
}

// What a difference in the data section means for the user.
std::string data_meaning(const std::string& key) {
  if (key == "resolution") return "the training resolution (scene.yaml's camera and --downscale)";
  if (key == "views") return "the views and their hold-out split (the scene's frames, --holdout-every)";
  if (key == "cameras") return "the cameras (poses.txt or gt/poses.txt, --poses, scene.yaml's intrinsics)";
  if (key == "images") return "the target images (thermal/ frames, --intensity, the percentiles)";
  if (key == "world_offset_m") return "the scene's world_offset_m (scene.yaml)";
  return "the training data's " + key;
}

std::string show(const json& v) {
  if (v.is_string()) return v.get<std::string>();
  return v.dump();
}

// A data difference with both values in words where they have some (fingerprints have none).
std::string data_change(const std::string& key, const json& a, const json& b) {
  const std::string what = data_meaning(key);
  if (key == "views" && a.is_object() && b.is_object() && a.contains("count") && a.contains("heldout")) {
    auto views = [](const json& v) {
      return show(v.at("count")) + " views, " + show(v.at("heldout")) + " held out";
    };
    const std::string va = views(a), vb = views(b);
    return what + ": checkpoint " + va + ", now " + vb + (va == vb ? " (other frames or another split)" : "");
  }
  if (key == "cameras" || key == "images") return what + " differ from the checkpoint's";
  return what + ": checkpoint " + show(a) + ", now " + show(b);
}

}  // namespace

json run_options_json(const TrainOptions& o, const TrainingData& data) {
  json train = {{"iterations", o.iterations},
                {"lambda_geo", o.lambda_geo},
                {"lambda_ssim", o.lambda_ssim},
                {"geo_robust_scale_m", o.geo_robust_scale_m},
                {"geo_gradient_to_opacity", o.geo_gradient_to_opacity},
                {"sh_degree", o.sh_degree},
                {"sh_degree_every", o.sh_degree_every},
                {"densify_from", o.densify_from},
                {"densify_until", o.densify_until},
                {"densify_every", o.densify_every},
                {"opacity_reset_every", o.opacity_reset_every},
                {"densify_grad_threshold", shortest(o.densify_grad_threshold)},
                {"plane_prune_k", o.plane_prune_k},
                {"max_gaussians", o.max_gaussians},
                {"strategy", o.strategy},
                {"mcmc_growth", shortest(o.mcmc_growth)},
                {"mcmc_noise_lr", shortest(o.mcmc_noise_lr)},
                {"mcmc_opacity_reg", shortest(o.mcmc_opacity_reg)},
                {"mcmc_scale_reg", shortest(o.mcmc_scale_reg)},
                {"lr_scale", shortest(o.lr_scale)},
                {"eval_every", o.eval_every},
                {"checkpoint_every", o.checkpoint_every},
                {"deterministic", o.deterministic},
                {"seed", o.seed},
                {"progress_every", o.progress_every},
                {"recentred_output", o.recentred_output},
                {"level_model", o.level_model},
                {"level_lr_log_gain", shortest(o.level_lr_log_gain)},
                {"level_lr_offset", shortest(o.level_lr_offset)},
                {"level_lr_vignetting", shortest(o.level_lr_vignetting)},
                {"level_lambda_identity", shortest(o.level_lambda_identity)},
                {"level_lambda_smooth", shortest(o.level_lambda_smooth)}};
  if (o.growth.enabled)  // only then, so that other runs' stored options stay as they were
    train["growth"] = {{"start", o.growth.start},
                       {"factor", o.growth.factor},
                       {"phase_refinements", o.growth.phase_refinements},
                       {"until_fraction", o.growth.until_fraction},
                       {"validation_every", o.growth.validation_every},
                       {"min_gain_db", o.growth.min_gain_db},
                       {"noise_multiple", o.growth.noise_multiple},
                       {"min_transfer", o.growth.min_transfer},
                       {"roll_back", o.growth.roll_back},
                       {"last_doubling", o.growth.last_doubling}};
  const TrainingDataOptions& d = data.options;
  json data_options = {{"downscale", d.downscale},
                       {"holdout_every", d.holdout_every},
                       {"intensity", mapping_name(d.mapping)},
                       {"low_percentile", d.low_percentile},
                       {"high_percentile", d.high_percentile},
                       {"frozen_threshold", d.frozen_threshold},
                       {"pose_match_tolerance_s", d.pose_match_tolerance_s},
                       {"poses", d.true_poses ? "truth" : "estimated"}};
  // The data's identity: resolution, views (names and split), cameras and images as fingerprints.
  Fnv1a names, cameras, images;
  size_t heldout = 0;
  for (const auto& v : data.views) {
    names.bytes(v.name.data(), v.name.size());
    names.value('\0');
    names.value(v.heldout);
    heldout += v.heldout;
    const kernels::SplatCamera& c = v.camera;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) cameras.value(c.R_cam_world[i][j]);
    for (int i = 0; i < 3; ++i) cameras.value(c.t_cam_world[i]);
    for (double x : {c.fx, c.fy, c.cx, c.cy}) cameras.value(x);
    images.bytes(v.image.data(), v.image.size() * sizeof(float));
  }
  json identity = {
      {"resolution", {data.width, data.height}},
      {"views", {{"count", data.views.size()}, {"heldout", heldout}, {"fnv1a", names.hex()}}},
      {"cameras", cameras.hex()},
      {"images", images.hex()},
      {"world_offset_m", {data.world_offset_m.x(), data.world_offset_m.y(), data.world_offset_m.z()}}};
  return {{"train", train}, {"data_options", data_options}, {"data", identity}};
}

std::vector<std::string> check_resume_options(const std::filesystem::path& checkpoint,
                                              uint32_t checkpoint_iteration, const json& stored,
                                              const json& now) {
  static const std::set<std::string> may_change = {"iterations", "eval_every", "checkpoint_every",
                                                   "progress_every", "recentred_output"};
  std::vector<std::string> notes, refused;
  for (const char* section : {"train", "data_options", "data"}) {
    if (!stored.contains(section) || !stored.at(section).is_object()) {
      notes.push_back(std::string("the checkpoint records no '") + section + "' options; assumed unchanged");
      continue;
    }
    const json& a = stored.at(section);
    const json& b = now.at(section);
    std::set<std::string> keys;
    for (const auto& [k, v] : a.items()) keys.insert(k);
    for (const auto& [k, v] : b.items()) keys.insert(k);
    for (const std::string& key : keys) {
      if (!a.contains(key)) {
        notes.push_back(std::string(section) + "." + key +
                        " is not recorded in the checkpoint; assumed unchanged");
        continue;
      }
      if (!b.contains(key)) {
        notes.push_back(std::string(section) + "." + key +
                        " of the checkpoint is no longer an option; ignored");
        continue;
      }
      if (a.at(key) == b.at(key)) continue;
      if (std::string(section) == "data") {
        refused.push_back(data_change(key, a.at(key), b.at(key)));
        continue;
      }
      const std::string flag = flag_of(section, key);
      const std::string what = flag.empty() ? key + " (no CLI flag)" : flag;
      const std::string change = what + ": checkpoint " + show(a.at(key)) + ", now " + show(b.at(key));
      if (std::string(section) == "train" && may_change.count(key)) {
        if (key == "iterations") {
          const uint32_t n = b.at(key).get<uint32_t>();
          if (n < checkpoint_iteration) {
            refused.push_back(change + " (below the checkpoint's iteration " +
                              std::to_string(checkpoint_iteration) + ")");
            continue;
          }
          notes.push_back(
              change + ": the run " + (n > a.at(key).get<uint32_t>() ? "is extended" : "is shortened") +
              "; from iteration " + std::to_string(checkpoint_iteration) +
              " on, the means' learning-rate decay and the refinement window follow the new total, so"
              " the result differs from a run started with --iterations " +
              std::to_string(n));
        } else {
          notes.push_back(change);
        }
        continue;
      }
      refused.push_back(change);
    }
  }
  if (!refused.empty()) {
    std::ostringstream m;
    m << checkpoint.string() << ": train --resume refused: " << refused.size()
      << (refused.size() == 1 ? " setting differs" : " settings differ") << " from the checkpoint's run:";
    for (const auto& r : refused) m << "\n  " << r;
    m << "\nResume with the checkpoint's settings, or train into another --out. Only --iterations (to extend "
         "the run),"
         " --eval-every, --checkpoint-every, --progress-every and --recentred-output may change on resume.";
    throw std::invalid_argument(m.str());
  }
  return notes;
}

std::string start_fingerprint(const kernels::GaussianModel& initial, const PlanarMap* planes) {
  Fnv1a f;
  f.value(initial.channels);
  f.value(initial.sh_degree);
  for (const std::vector<float>* a :
       {&initial.means, &initial.log_scales, &initial.quats, &initial.opacity_logits, &initial.sh}) {
    f.value(a->size());
    f.bytes(a->data(), a->size() * sizeof(float));
  }
  if (planes) {
    f.value(planes->points.size());
    f.bytes(planes->points.data(), planes->points.size() * sizeof(Eigen::Vector3f));
    f.bytes(planes->normals.data(), planes->normals.size() * sizeof(Eigen::Vector3f));
    f.bytes(planes->centres.data(), planes->centres.size() * sizeof(Eigen::Vector3f));
    f.bytes(planes->planar.data(), planes->planar.size());
  }
  return f.hex();
}

}  // namespace litgs::host
