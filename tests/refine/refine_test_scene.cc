#include "refine_test_scene.h"

#include <cmath>

#include "host/refine/ate.h"
#include "host/synth/rng.h"

namespace litgs::host::refine::testing {

double ate(const std::vector<CameraPose>& poses, const std::vector<CameraPose>& truth) {
  return absolute_trajectory_error(as_tum_poses(poses), as_tum_poses(truth), AteAlignment::kSE3).rmse_m;
}

void make_test_scene(TestScene& s, const TestSceneOptions& o) {
  synth::World& w = s.world;
  w.add_texture({});
  // The facade: the plane y = 8, facing -y; the ground z = 0; a side wall x = 12 and a box.
  synth::Rect facade;
  facade.origin = {-10, 8, 0};
  facade.u_axis = {1, 0, 0};
  facade.v_axis = {0, 0, 1};
  facade.u_len_m = 30;
  facade.v_len_m = 8;
  w.add_rect(facade);
  if (!o.single_plane) {
    synth::Rect ground;
    ground.origin = {-10, -5, 0};
    ground.u_axis = {1, 0, 0};
    ground.v_axis = {0, 1, 0};
    ground.u_len_m = 30;
    ground.v_len_m = 13;
    w.add_rect(ground);
    synth::Rect side;
    side.origin = {12, -5, 0};
    side.u_axis = {0, 1, 0};
    side.v_axis = {0, 0, 1};
    side.u_len_m = 13;
    side.v_len_m = 8;
    w.add_rect(side);
    w.add_box({4, 5, 0}, {1.5, 1.2, 1.4}, 0.3, 0);
  }
  w.build_index();

  s.camera = {200, 200, 159.5, 127.5, 320, 256};
  synth::Rng rng(o.seed);
  // Camera looking +y (x right, y down, z forward), 1.5 m up, moving along +x, optionally yawing.
  Eigen::Matrix3d R0;
  R0.col(0) = Eigen::Vector3d(1, 0, 0);
  R0.col(1) = Eigen::Vector3d(0, 0, -1);
  R0.col(2) = Eigen::Vector3d(0, 1, 0);
  double travelled = 0;
  for (size_t f = 0; f < o.frames; ++f) {
    CameraPose t;
    t.t_s = 100 + 0.1 * static_cast<double>(f);
    const double yaw = o.rotate_rad_per_frame * static_cast<double>(f) -
                       0.5 * o.rotate_rad_per_frame * static_cast<double>(o.frames);
    t.q_world_cam =
        Eigen::Quaterniond(Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix() * R0);
    const double phase = 2 * M_PI * static_cast<double>(f) / static_cast<double>(o.frames);
    t.p_world_cam = Eigen::Vector3d(o.speed_m_per_frame * static_cast<double>(f),
                                    o.speed_m_per_frame > 0 ? o.weave_m * std::sin(phase) : 0, 1.5);
    if (f > 0) travelled += (t.p_world_cam - s.truth.back().p_world_cam).norm();
    s.truth.push_back(t);
    CameraPose e = t;
    e.p_world_cam += (o.initial_offset_m + o.drift_per_m * travelled * travelled) * o.drift_dir +
                     o.jitter_m * Eigen::Vector3d(rng.normal(), rng.normal(), rng.normal());
    e.q_world_cam =
        Eigen::AngleAxisd(o.rotation_drift_per_m * travelled, Eigen::Vector3d::UnitZ()) * e.q_world_cam;
    s.priors.push_back(e);
  }
  // The LiDAR map: the visible surfaces sampled on a grid with 5 mm noise, plane fits.
  std::vector<Eigen::Vector3d> map;
  for (const auto& r : w.rects)
    for (double u = 0; u <= r.u_len_m; u += 0.1)
      for (double v = 0; v <= r.v_len_m; v += 0.1)
        map.push_back(r.origin + u * r.u_axis + v * r.v_axis +
                      0.005 * rng.normal() * r.u_axis.cross(r.v_axis).normalized());
  s.map = fit_planes(map, {});
  // Anchors: surface points seen from random frames, their estimate drawn from their covariance.
  for (size_t a = 0; a < o.anchors; ++a) {
    const CameraPose& c = s.truth[static_cast<size_t>(rng.uniform_int(0, static_cast<int>(o.frames) - 1))];
    const Eigen::Vector3d d((rng.uniform(20, 300) - 159.5) / 200, (rng.uniform(20, 236) - 127.5) / 200, 1);
    const auto hit = w.cast({c.p_world_cam, (c.q_world_cam * d).normalized()}, 0.3, 40);
    if (!hit) continue;
    AnchorPoint ap;
    Eigen::Vector3d sig = Eigen::Vector3d::Constant(o.anchor_sigma_m);
    if (o.anchor_min_sigma_m > 0) sig.z() = o.anchor_min_sigma_m;
    ap.cov = sig.cwiseAbs2().asDiagonal();
    ap.p_world =
        hit->point + Eigen::Vector3d(sig.x() * rng.normal(), sig.y() * rng.normal(), sig.z() * rng.normal());
    s.anchors.push_back(ap);
    s.anchors_true.push_back(hit->point);
  }
  s.input.camera = s.camera;
  s.input.priors = s.priors;
  s.input.anchors = s.anchors;
  s.input.map = &s.map;
  s.input.points = synthetic_tracks(w, s.truth, s.priors, s.camera, s.anchors_true, o.tracks);
}

}  // namespace litgs::host::refine::testing
