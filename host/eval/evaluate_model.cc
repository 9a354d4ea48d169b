#include "host/eval/evaluate_model.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <memory>
#include <stdexcept>

#include "engine/context.h"
#include "host/eval/covisibility.h"
#include "host/train/evaluation.h"
#include "host/train/lidar_planes.h"
#include "host/train/output_frame.h"
#include "host/train/true_planes.h"
#include "io/gaussian_ply.h"
#include "io/image.h"
#include "io/pcd.h"
#include "io/scene.h"
#include "kernels/loss/loss_reference.h"
#include "kernels/splat/rasterizer.h"

namespace litgs::host {
namespace {

double median(std::vector<double> v) {
  if (v.empty()) return -1;
  std::sort(v.begin(), v.end());
  const size_t m = v.size() / 2;
  return v.size() % 2 ? v[m] : 0.5 * (v[m - 1] + v[m]);
}

// The centres' distances to the planes (host::PlaneDistance: the plane of the nearest reference point within
// 0.5 m; centres with none, or nearest a non-planar point, are not counted).
void centre_plane_residuals(const kernels::GaussianModel& model, const PlanarMap& planes,
                            ModelEvaluation& e) {
  const std::vector<float> d = PlaneDistance(planes).distances(model.means);
  std::vector<double> counted;
  double ss = 0;
  for (float v : d)
    if (std::isfinite(v)) {
      counted.push_back(v);
      ss += double{v} * v;
    }
  e.centre_plane_counted = counted.size();
  if (counted.empty()) return;
  e.centre_plane_rms_m = std::sqrt(ss / static_cast<double>(counted.size()));
  e.centre_plane_median_m = median(std::move(counted));
}

}  // namespace

void EvalOptions::check() const {
  data.check();
  emd.check();
}

ModelEvaluation evaluate_model(const std::filesystem::path& model_ply, const std::filesystem::path& scene_dir,
                               const EvalOptions& o, std::vector<ViewImages>* images) {
  o.check();
  const TrainingData data = load_training_data(scene_dir, o.data);
  io::SceneReadOptions read;
  read.check_images = false;
  const io::Scene scene = io::read_scene(scene_dir, read);
  std::vector<uint32_t> heldout;
  for (uint32_t i = 0; i < data.views.size(); ++i)
    if (data.views[i].heldout) heldout.push_back(i);
  if (heldout.empty())
    throw std::invalid_argument(scene_dir.string() + ": no held-out views to evaluate (holdout_every " +
                                std::to_string(o.data.holdout_every) + ", " +
                                std::to_string(data.views.size()) + " views)");

  // The model, moved into the scene's frame (the frame of its poses and map) in double precision.
  kernels::GaussianModel model = io::read_gaussian_ply(model_ply);
  const ModelFrame frame = read_model_frame(model_ply);
  model = shift_means(std::move(model), frame.world_offset_m - scene.config.world_offset_m);

  ModelEvaluation e;
  e.width = data.width;
  e.height = data.height;
  e.bit_depth = io::read_image_info(scene_dir / scene.frames.front().image).bit_depth;
  e.stretch_low = data.stretch_low;
  e.stretch_high = data.stretch_high;
  e.gaussians = model.size();

  // The LiDAR scans the map held out, where there are any: measurements the training never saw.
  std::optional<io::PointCloud> heldout_scans;
  if (o.geometry && std::filesystem::exists(scene_dir / io::kHeldoutScansMap))
    heldout_scans = io::read_pcd(scene_dir / io::kHeldoutScansMap);
  std::unique_ptr<PlanarMap> planes = true_planar_map(scene);
  if (planes) {
    e.plane_reference = "gt/planes.txt";
  } else if (heldout_scans) {
    planes = std::make_unique<PlanarMap>(fit_planes(heldout_scans->positions, PlaneFitOptions{}));
    e.plane_reference = std::string("LiDAR plane fits of the held-out scans (") + io::kHeldoutScansMap + ")";
  } else if (scene.map && o.geometry) {
    planes = std::make_unique<PlanarMap>(fit_planes(scene.map->positions, PlaneFitOptions{}));
    e.plane_reference = "LiDAR plane fits of the training map (lidar/map.pcd: circular)";
  }

  engine::Context context;
  e.device = context.info().name;
  kernels::DeviceGaussians gaussians(context, model);
  kernels::Rasterizer rasterizer(context, model.channels);
  auto camera_of = [&](uint32_t view) {
    kernels::SplatCamera cam = data.views[view].camera;
    cam.sh_degree = model.sh_degree;
    return cam;
  };
  // One warm-up render, so that the timings do not include pipeline creation and first allocations.
  rasterizer.forward(gaussians, camera_of(heldout.front()));
  (void)rasterizer.download_images();

  const HeldoutCovisibility covisibility = heldout_covisibility(scene_dir, scene, data);
  e.covisibility_unavailable = covisibility.unavailable;

  const uint32_t W = data.width, H = data.height;
  double plane_sq = 0;
  size_t plane_n = 0;
  std::vector<double> times;
  if (images) images->clear();
  for (uint32_t i : heldout) {
    const TrainingView& view = data.views[i];
    const kernels::SplatCamera cam = camera_of(i);
    const auto start = std::chrono::steady_clock::now();
    rasterizer.forward(gaussians, cam);
    const kernels::RenderImages<float> img = rasterizer.download_images();
    ViewMetrics m;
    m.render_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    m.name = view.name;
    m.t_s = view.t_s;
    const std::vector<float> shown = shown_as_written(img.image);
    m.psnr_db = kernels::psnr(shown, view.image);
    m.ssim = kernels::ssim_reference(shown, view.image, 1, W, H);
    if (e.bit_depth == 16) {
      double sum = 0;
      for (size_t p = 0; p < view.image.size(); ++p) sum += std::abs(double{shown[p]} - view.image[p]);
      m.mae_counts = sum / static_cast<double>(view.image.size()) * (data.stretch_high - data.stretch_low);
    }
    if (!covisibility.masks.empty()) {
      const std::vector<uint8_t>& mask = covisibility.masks[i];
      m.covisible_fraction = static_cast<double>(std::count(mask.begin(), mask.end(), uint8_t{1})) /
                             static_cast<double>(mask.size());
      m.covisible_psnr_db = masked_psnr(shown, view.image, mask);
    }
    if (planes) {
      const PlaneResidualSum r = depth_plane_residuals(*planes, cam, img.depth, img.alpha);
      if (r.count > 0) m.depth_plane_rmse_m = std::sqrt(r.sum_sq_m2 / static_cast<double>(r.count));
      plane_sq += r.sum_sq_m2;
      plane_n += r.count;
    }
    times.push_back(m.render_ms);
    e.views.push_back(m);
    if (images)
      images->push_back({view.name, W, H, shown, view.image, img.depth, img.alpha,
                         covisibility.masks.empty() ? std::vector<uint8_t>{} : covisibility.masks[i]});
  }
  const double n = static_cast<double>(e.views.size());
  for (const ViewMetrics& m : e.views) {
    e.psnr_db += m.psnr_db / n;
    e.ssim += m.ssim / n;
    if (e.bit_depth == 16) e.mae_counts = std::max(e.mae_counts, 0.0) + m.mae_counts / n;
  }
  if (!covisibility.masks.empty()) {
    double psnr_sum = 0, fraction_sum = 0;
    size_t psnr_n = 0;
    for (const ViewMetrics& m : e.views) {
      fraction_sum += m.covisible_fraction;
      if (std::isfinite(m.covisible_psnr_db)) {
        psnr_sum += m.covisible_psnr_db;
        ++psnr_n;
      }
    }
    e.covisible_fraction = fraction_sum / n;
    if (psnr_n > 0) e.covisible_psnr_db = psnr_sum / static_cast<double>(psnr_n);
  }
  if (plane_n > 0) e.depth_plane_rmse_m = std::sqrt(plane_sq / static_cast<double>(plane_n));
  e.render_ms_median = median(times);

  if (o.geometry) {
    const io::PointCloud* reference = nullptr;
    if (scene.gt && scene.gt->map) {
      reference = &*scene.gt->map;
      e.geometry_reference = "gt/map.pcd";
    } else if (heldout_scans) {
      reference = &*heldout_scans;
      e.geometry_reference = io::kHeldoutScansMap;
    } else if (scene.map) {
      reference = &*scene.map;
      e.geometry_reference = "lidar/map.pcd";
      e.geometry_reference_trained = true;
    }
    if (reference && model.size() > 0) {
      std::vector<Eigen::Vector3d> centres(model.size());
      std::vector<double> opacities(model.size());
      for (size_t g = 0; g < model.size(); ++g) {
        centres[g] = {model.means[3 * g], model.means[3 * g + 1], model.means[3 * g + 2]};
        opacities[g] = 1.0 / (1.0 + std::exp(-double{model.opacity_logits[g]}));
      }
      // The first surfaces of each training view come from the densest cloud at hand.
      const io::PointCloud& surfaces = scene.gt && scene.gt->map ? *scene.gt->map
                                       : scene.map               ? *scene.map
                                                                 : *reference;
      std::vector<kernels::SplatCamera> training_cameras;
      for (const TrainingView& v : data.views)
        if (!v.heldout) training_cameras.push_back(v.camera);
      const ObservedRegion region(surfaces.positions, training_cameras, o.region);
      std::vector<size_t> observed, inside;
      e.region = measure_region(region, reference->positions, centres, opacities, o.region, observed, inside);
      if (!observed.empty() && !inside.empty()) {
        std::vector<Eigen::Vector3d> observed_points, inside_centres;
        std::vector<double> inside_opacities;
        for (size_t i : observed) observed_points.push_back(reference->positions[i]);
        for (size_t g : inside) {
          inside_centres.push_back(centres[g]);
          inside_opacities.push_back(opacities[g]);
        }
        if (std::any_of(inside_opacities.begin(), inside_opacities.end(), [](double a) { return a > 0; }))
          e.emd = gaussian_emd(inside_centres, inside_opacities, observed_points, o.emd);
      }
    }
    if (planes) centre_plane_residuals(model, *planes, e);
  }
  return e;
}

nlohmann::json to_json(const ModelEvaluation& e) {
  using nlohmann::json;
  auto optional_number = [](double v) { return v >= 0 ? json(v) : json(nullptr); };
  // -1 (not measured) and NaN (no covisible pixel) as null; a PSNR may be any finite number.
  auto finite_or_null = [](double v) { return std::isfinite(v) && v != -1 ? json(v) : json(nullptr); };
  json views = json::array();
  for (const ViewMetrics& m : e.views)
    views.push_back({{"name", m.name},
                     {"t_s", m.t_s},
                     {"psnr_db", m.psnr_db},
                     {"ssim", m.ssim},
                     {"mae_counts", optional_number(m.mae_counts)},
                     {"depth_plane_rmse_m", optional_number(m.depth_plane_rmse_m)},
                     {"covisible_fraction", optional_number(m.covisible_fraction)},
                     {"covisible_psnr_db", finite_or_null(m.covisible_psnr_db)},
                     {"render_ms", m.render_ms}});
  json j = {
      {"views", views},
      {"heldout_views", e.views.size()},
      {"psnr_db", e.psnr_db},
      {"ssim", e.ssim},
      {"mae_counts", optional_number(e.mae_counts)},
      {"depth_plane_rmse_m", optional_number(e.depth_plane_rmse_m)},
      {"covisible_fraction", optional_number(e.covisible_fraction)},
      {"covisible_psnr_db", finite_or_null(e.covisible_psnr_db)},
      {"covisibility",
       e.covisibility_unavailable.empty()
           ? json("PSNR over the held-out pixels whose true surface point (gt/depth, gt/poses.txt) "
                  "a training view also sees (DyCheck's co-visibility mask)")
           : json("not measured: " + e.covisibility_unavailable)},
      {"lpips", kLpipsNote},
      {"image_units", e.bit_depth == 16 ? "intensity in [0, 1]: raw counts stretched from [stretch_low, "
                                          "stretch_high]; mae_counts in raw counts"
                                        : "intensity in [0, 1]: 8-bit value / 255"},
      {"bit_depth", e.bit_depth},
      {"stretch_low", e.stretch_low},
      {"stretch_high", e.stretch_high},
      {"width", e.width},
      {"height", e.height},
      {"gaussians", e.gaussians},
      {"render_ms_per_frame", e.render_ms_median},
      {"device", e.device},
      {"plane_reference", e.plane_reference.empty() ? json(nullptr) : json(e.plane_reference)},
      {"centre_plane_rms_m", optional_number(e.centre_plane_rms_m)},
      {"centre_plane_median_m", optional_number(e.centre_plane_median_m)},
      {"centre_plane_counted", e.centre_plane_counted},
  };
  if (e.region)
    j["observed_region"] = {
        {"reference_points", e.region->reference_points},
        {"reference_observed", e.region->reference_observed},
        {"reference_observed_fraction", e.region->reference_observed_fraction()},
        {"gaussians", e.region->gaussians},
        {"gaussians_in_region", e.region->gaussians_in_region},
        {"covered_fraction", e.region->covered_fraction()},
        {"coverage_radius_m", e.region->coverage_radius_m},
        {"coverage_min_opacity", e.region->coverage_min_opacity},
        {"definition",
         "reference points and Gaussian centres that some training view sees: inside its image, no more "
         "than a margin behind the nearest surface point in their z-buffer cell; covered_fraction: the "
         "observed reference points with a Gaussian centre (opacity >= the threshold) within the radius"}};
  else
    j["observed_region"] = nullptr;
  j["geometry_reference_trained"] = e.geometry_reference_trained;
  if (e.emd)
    j["emd"] = {
        {"mean_m", e.emd->mean_m},
        {"std_m", e.emd->std_m},
        {"floor_m", e.emd->floor_m},
        {"samples", e.emd->samples},
        {"rounds", e.emd->rounds},
        {"reference", e.geometry_reference},
        {"definition",
         "mean Euclidean distance (m) of the exact optimal one-to-one matching between N Gaussian "
         "centres drawn in proportion to opacity and N reference points drawn uniformly, both inside the "
         "observed region; floor_m: the same between two draws of the reference (the sampling floor)"}};
  else
    j["emd"] = nullptr;
  return j;
}

}  // namespace litgs::host
