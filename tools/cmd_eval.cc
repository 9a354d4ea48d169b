// `litgs-engine eval --model M.ply --scene SCENE`: a trained model's quality on the scene's held-out views,
// its geometry against the reference cloud and planes, and its render speed (host/eval/evaluate_model.h);
// without --model, only the scene's trajectories (host/eval/trajectory_eval.h).
#include <CLI/CLI.hpp>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <memory>

#include "host/eval/eval_option_names.h"
#include "host/eval/evaluate_model.h"
#include "host/eval/trajectory_eval.h"
#include "host/eval/view_images.h"
#include "host/partition/seam_metrics.h"
#include "host/train/training_data.h"
#include "io/atomic_file.h"
#include "io/scene.h"
#include "tools/commands.h"
#include "tools/data_flags.h"

namespace litgs::tools {
namespace {

struct EvalCliOptions {
  std::string model, scene;
  bool json = false;
  std::string out;        // eval.json, written atomically
  std::string views_out;  // folder for the held-out views' pictures
  std::string partition;  // a partition folder: PSNR per block and along the seams
  DataFlags data_flags;
  host::EvalOptions eval;
};

std::string fixed(double v, int digits) {
  if (v < 0) return "-";
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.*f", digits, v);
  return buf;
}

// The trajectory line: ATE against the truth, or how far refinement moved the frames, or why neither.
void print_trajectory(const nlohmann::json& trajectory) {
  if (trajectory.is_object() && !trajectory["ate_m"].is_number()) {
    std::cout << "eval: ATE not available: the scene has no gt/poses.txt; refinement moved the frames "
              << fixed(trajectory["moved_mean_m"].get<double>(), 4) << " m on average (at most "
              << fixed(trajectory["moved_max_m"].get<double>(), 4) << " m)\n";
  } else if (trajectory.is_object()) {
    std::cout << "eval: ATE " << fixed(trajectory["ate_m"].get<double>(), 4) << " m";
    if (trajectory["ate_prior_m"].is_number())
      std::cout << " (before refinement " << fixed(trajectory["ate_prior_m"].get<double>(), 4) << " m)";
    std::cout << " against gt/poses.txt (" << trajectory["frame"].get<std::string>() << " poses), "
              << trajectory["alignment"].get<std::string>() << "\n";
  } else {
    std::cout << "eval: ATE " << trajectory.get<std::string>() << "\n";
  }
}

void print_text(const host::ModelEvaluation& e, const nlohmann::json& trajectory) {
  const bool counts = e.bit_depth == 16;
  std::cout << "eval: " << e.views.size() << " held-out views at " << e.width << "x" << e.height << ", "
            << e.gaussians << " Gaussians, on " << e.device << "\n"
            << "eval: images compared as intensity in [0, 1] ("
            << (counts
                    ? "raw counts " + fixed(e.stretch_low, 0) + ".." + fixed(e.stretch_high, 0) + " stretched"
                    : "8-bit value / 255")
            << "); PSNR in dB (peak 1), SSIM 11-tap Gaussian window (sigma 1.5)"
            << (counts ? ", MAE in raw counts" : "") << ", depth residual in m\n";
  std::printf("%-28s %9s %7s %10s %12s %10s %10s %9s\n", "view", "PSNR dB", "SSIM", "MAE count",
              "depth rms m", "render ms", "covis dB", "covis %");
  auto percent = [](double fraction) { return fixed(fraction < 0 ? fraction : 100 * fraction, 1); };
  for (const host::ViewMetrics& m : e.views)
    std::printf("%-28s %9.3f %7.4f %10s %12s %10.2f %10s %9s\n", m.name.c_str(), m.psnr_db, m.ssim,
                fixed(m.mae_counts, 1).c_str(), fixed(m.depth_plane_rmse_m, 4).c_str(), m.render_ms,
                fixed(m.covisible_psnr_db, 3).c_str(), percent(m.covisible_fraction).c_str());
  std::printf("%-28s %9.3f %7.4f %10s %12s %10.2f %10s %9s (render: median)\n", "mean", e.psnr_db, e.ssim,
              fixed(e.mae_counts, 1).c_str(), fixed(e.depth_plane_rmse_m, 4).c_str(), e.render_ms_median,
              fixed(e.covisible_psnr_db, 3).c_str(), percent(e.covisible_fraction).c_str());
  if (e.covisibility_unavailable.empty())
    std::cout << "eval: covis: PSNR over the held-out pixels whose true surface point a training view also "
                 "sees (gt/depth), and their share\n";
  else
    std::cout << "eval: covisible PSNR not measured: " << e.covisibility_unavailable << "\n";
  if (e.emd)
    std::cout << "eval: EMD " << fixed(e.emd->mean_m, 4) << " m (sampling floor " << fixed(e.emd->floor_m, 4)
              << " m, std " << fixed(e.emd->std_m, 4) << " over " << e.emd->rounds << " draws of "
              << e.emd->samples << " points; Gaussian centres "
              << (e.emd->weighted_by_opacity ? "by opacity" : "uniformly") << " against "
              << e.geometry_reference << ", exact assignment; both inside the observed region)\n";
  else
    std::cout << "eval: EMD not measured (--no-geometry, no reference cloud, or nothing in the observed "
                 "region)\n";
  if (e.region)
    std::cout << "eval: observed region: " << percent(e.region->reference_observed_fraction()) << " % of "
              << e.geometry_reference << " (" << e.region->reference_observed << " of "
              << e.region->reference_points << " points) is seen by a training view, "
              << e.region->gaussians_in_region << " of " << e.region->gaussians
              << " Gaussians lie in it; coverage " << percent(e.region->covered_fraction())
              << " % of the seen points have a Gaussian centre within "
              << fixed(e.region->coverage_radius_m, 2) << " m\n";
  if (e.geometry_reference_trained)
    std::cout << "eval: note: the geometry reference is the map that trained the model (circular): rebuild "
                 "it with `litgs-engine map --force` to hold scans out\n";
  if (e.centre_plane_counted > 0)
    std::cout << "eval: Gaussian centres to planes (" << e.plane_reference << "): RMS "
              << fixed(e.centre_plane_rms_m, 4) << " m, median " << fixed(e.centre_plane_median_m, 4)
              << " m over " << e.centre_plane_counted << " of " << e.gaussians << " centres\n";
  print_trajectory(trajectory);
  std::cout << "eval: LPIPS " << host::kLpipsNote << "\n";
}

void run_eval(const EvalCliOptions& cli) {
  host::EvalOptions o = cli.eval;
  apply_data_flags(cli.data_flags, o.data);
  if (cli.model.empty()) {  // the poses only
    const nlohmann::json j = {{"trajectory", host::trajectory_json_or_reason(cli.scene, o.data.true_poses)}};
    if (!cli.out.empty()) io::write_file_atomic(cli.out, [&](std::ostream& s) { s << j.dump(2) << "\n"; });
    if (cli.json)
      std::cout << j.dump(2) << "\n";
    else
      print_trajectory(j["trajectory"]);
    return;
  }
  std::vector<host::ViewImages> images;
  const bool keep_images = !cli.views_out.empty() || !cli.partition.empty();
  const host::ModelEvaluation e =
      host::evaluate_model(cli.model, cli.scene, o, keep_images ? &images : nullptr);
  nlohmann::json j = host::to_json(e);
  if (!cli.partition.empty()) {
    const io::Scene scene = io::read_scene(cli.scene, {.check_images = false, .load_map = false});
    std::vector<kernels::SplatCamera> cameras;
    for (const host::ViewMetrics& v : e.views)
      cameras.push_back(host::training_camera(cli.scene, scene, v.t_s, o.data));
    j["partition"] = host::partition::to_json(host::partition::seam_metrics(cli.partition, images, cameras));
  }
  j["trajectory"] = host::trajectory_json_or_reason(cli.scene, o.data.true_poses);
  if (!cli.views_out.empty()) {
    std::filesystem::create_directories(cli.views_out);
    nlohmann::json pictures = nlohmann::json::array();
    for (const host::ViewImages& v : images) pictures.push_back(host::write_view_images(cli.views_out, v));
    j["pictures"] = {
        {"folder", cli.views_out}, {"views", pictures}, {"error_full_scale", host::kErrorFullScale}};
  }
  if (!cli.out.empty()) io::write_file_atomic(cli.out, [&](std::ostream& s) { s << j.dump(2) << "\n"; });
  if (cli.json) {
    std::cout << j.dump(2) << "\n";
    return;
  }
  print_text(e, j["trajectory"]);
  if (j.contains("partition")) {
    const nlohmann::json& p = j["partition"];
    auto line = [](const nlohmann::json& r) {
      return r["name"].get<std::string>() + " " +
             (r["psnr_db"].is_null() ? std::string("-") : fixed(r["psnr_db"].get<double>(), 2)) + " dB (" +
             std::to_string(r["pixels"].get<size_t>()) + " px)";
    };
    std::cout << "eval: held-out PSNR by block:";
    for (const auto& b : p["blocks"]) std::cout << " " << line(b) << ";";
    std::cout << " within " << fixed(p["seam_width_m"].get<double>(), 2)
              << " m of a seam: " << line(p["seams"]) << ", elsewhere: " << line(p["interior"]) << "\n";
  }
}

}  // namespace

void add_eval_command(CLI::App& app) {
  namespace E = host::eval_option;
  auto o = std::make_shared<EvalCliOptions>();
  CLI::App* cmd = app.add_subcommand(
      "eval",
      "Evaluate a trained model on its scene's held-out views, or (without --model) the scene's poses");
  cmd->add_option("--model", o->model,
                  "3DGS PLY model (train's point_cloud.ply); without it only the poses are scored")
      ->check(CLI::ExistingFile);
  cmd->add_option("--scene", o->scene, "Scene directory the model was trained on")
      ->required()
      ->check(CLI::ExistingDirectory);
  cmd->add_flag("--json", o->json, "Print the results as JSON");
  cmd->add_option("--out", o->out, "Also write the JSON results to this file (atomically)");
  cmd->add_option("--views-out", o->views_out,
                  "Write each held-out view's render, frame, error map, false colour and depth as PNG here");
  cmd->add_option(
         "--partition", o->partition,
         "A partition folder (partition, train-blocks): the held-out PSNR per block and along the seams")
      ->check(CLI::ExistingDirectory);
  add_data_flags(cmd, o->eval.data, o->data_flags);
  cmd->add_option(E::kEmdSamples.flag, o->eval.emd.samples, E::kEmdSamples.help)->capture_default_str();
  cmd->add_option(E::kEmdRounds.flag, o->eval.emd.rounds, E::kEmdRounds.help)->capture_default_str();
  cmd->add_option(E::kSeed.flag, o->eval.emd.seed, E::kSeed.help)->capture_default_str();
  cmd->add_flag(E::kGeometry.flag, o->eval.geometry, E::kGeometry.help);
  cmd->add_flag("!--emd-uniform", o->eval.emd.weight_by_opacity,
                "EMD: draw Gaussian centres uniformly instead of in proportion to opacity (a diagnostic)");
  cmd->callback([o] { run_eval(*o); });
}

}  // namespace litgs::tools
