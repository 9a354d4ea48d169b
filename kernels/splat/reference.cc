#include "kernels/splat/reference.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <numeric>
#include <stdexcept>

#include "kernels/splat/splat_math.h"
#include "kernels/splat/splat_shared.h"

namespace litgs::kernels {
namespace {

namespace sm = splat_math;

sm::ViewGeometry view_geometry(const SplatCamera& c) {
  sm::ViewGeometry v;
  v.R = c.R_cam_world;
  v.t = c.t_cam_world;
  v.fx = c.fx;
  v.fy = c.fy;
  v.cx = c.cx;
  v.cy = c.cy;
  v.near_m = c.near_m;
  v.width = c.width;
  v.height = c.height;
  return v;
}

glm::dvec3 vec3_at(const std::vector<float>& v, size_t i) {
  return {v[3 * i], v[3 * i + 1], v[3 * i + 2]};
}
glm::dvec4 vec4_at(const std::vector<float>& v, size_t i) {
  return {v[4 * i], v[4 * i + 1], v[4 * i + 2], v[4 * i + 3]};
}

// Everything the per-pixel pass needs, computed once per render.
struct Prepared {
  std::vector<sm::Projected> proj;
  std::vector<std::array<uint32_t, 4>> rect;      // tiles x0 y0 x1 y1, half-open
  std::vector<std::vector<double>> color;         // [N][C]
  std::vector<std::vector<uint32_t>> tile_lists;  // per tile: Gaussians in depth order
  uint32_t tiles_x = 0, tiles_y = 0;
  uint32_t culled_nonfinite = 0;
  uint64_t intersections = 0;
};

glm::dvec3 camera_centre(const SplatCamera& c) {
  return -glm::transpose(c.R_cam_world) * c.t_cam_world;
}

Prepared prepare(const GaussianModel& m, const SplatCamera& cam) {
  m.check();
  cam.check();
  if (cam.sh_degree > m.sh_degree)
    throw std::invalid_argument("SplatCamera.sh_degree exceeds the model's SH degree");
  const sm::ViewGeometry v = view_geometry(cam);
  const size_t n = m.size();
  const uint32_t C = m.channels, K = m.sh_coeffs();
  Prepared p;
  p.tiles_x = (cam.width + SPLAT_TILE_SIZE - 1) / SPLAT_TILE_SIZE;
  p.tiles_y = (cam.height + SPLAT_TILE_SIZE - 1) / SPLAT_TILE_SIZE;
  p.proj.resize(n);
  p.rect.assign(n, {0, 0, 0, 0});
  p.color.assign(n, std::vector<double>(C, 0.0));
  const glm::dvec3 centre = camera_centre(cam);
  std::vector<uint32_t> visible;
  for (size_t i = 0; i < n; ++i) {
    const sm::Projected pr = sm::project_gaussian(v, vec3_at(m.means, i), vec3_at(m.log_scales, i),
                                                  vec4_at(m.quats, i), m.opacity_logits[i]);
    p.proj[i] = pr;
    bool sh_finite = true;
    for (uint32_t k = 0; k < K * C; ++k) sh_finite = sh_finite && std::isfinite(m.sh[i * K * C + k]);
    if (!pr.finite || !sh_finite) ++p.culled_nonfinite;
    if (!pr.visible || !sh_finite) continue;
    const double T = SPLAT_TILE_SIZE;
    auto clampi = [](double x, uint32_t hi) {
      return static_cast<uint32_t>(std::clamp(x, 0.0, static_cast<double>(hi)));
    };
    const std::array<uint32_t, 4> r = {clampi(std::floor((pr.mean2d.x - pr.extent.x) / T), p.tiles_x),
                                       clampi(std::floor((pr.mean2d.y - pr.extent.y) / T), p.tiles_y),
                                       clampi(std::floor((pr.mean2d.x + pr.extent.x) / T) + 1, p.tiles_x),
                                       clampi(std::floor((pr.mean2d.y + pr.extent.y) / T) + 1, p.tiles_y)};
    if (r[0] >= r[2] || r[1] >= r[3]) continue;
    p.rect[i] = r;
    visible.push_back(static_cast<uint32_t>(i));
    double basis[SPLAT_MAX_SH_COEFFS];
    const glm::dvec3 dir = glm::normalize(vec3_at(m.means, i) - centre);
    sm::sh_basis(cam.sh_degree, dir, basis);
    for (uint32_t c = 0; c < C; ++c) {
      double sum = 0.5;
      for (uint32_t k = 0; k < K; ++k) sum += basis[k] * m.sh[(i * K + k) * C + c];
      p.color[i][c] = std::max(sum, 0.0);
    }
  }
  // Depth order, ties by index: what the device's stable sort of float32 depth keys gives.
  std::stable_sort(visible.begin(), visible.end(), [&](uint32_t a, uint32_t b) {
    return static_cast<float>(p.proj[a].depth) < static_cast<float>(p.proj[b].depth);
  });
  p.tile_lists.assign(static_cast<size_t>(p.tiles_x) * p.tiles_y, {});
  for (uint32_t g : visible)
    for (uint32_t ty = p.rect[g][1]; ty < p.rect[g][3]; ++ty)
      for (uint32_t tx = p.rect[g][0]; tx < p.rect[g][2]; ++tx) {
        p.tile_lists[ty * p.tiles_x + tx].push_back(g);
        ++p.intersections;
      }
  return p;
}

// One contribution of the walk: list position, alpha before clamping decisions, sigma.
struct Hit {
  uint32_t gaussian;
  double alpha, sigma, vis;  // vis = exp(-sigma)
  glm::dvec2 d;
  bool clamped;
};

// Walks one pixel's tile list front to back with the kernels' rules. Returns the hits that contributed;
// `last` = entries walked, `T` = final transmittance.
std::vector<Hit> walk_pixel(const Prepared& p, uint32_t px, uint32_t py, uint32_t& last, double& T) {
  const auto& list = p.tile_lists[(py / SPLAT_TILE_SIZE) * p.tiles_x + px / SPLAT_TILE_SIZE];
  const glm::dvec2 centre(px + 0.5, py + 0.5);
  std::vector<Hit> hits;
  T = 1.0;
  last = 0;
  for (uint32_t i = 0; i < list.size(); ++i) {
    const uint32_t g = list[i];
    const sm::Projected& pr = p.proj[g];
    const glm::dvec2 d = centre - pr.mean2d;
    const double sigma = sm::gaussian_sigma(pr.conic, d);
    if (sigma < 0.0) continue;
    const double vis = std::exp(-sigma);
    const double raw = pr.opacity * vis;
    const double alpha = std::min(SPLAT_ALPHA_MAX, raw);
    if (alpha < SPLAT_ALPHA_MIN) continue;
    const double next_T = T * (1.0 - alpha);
    if (next_T < SPLAT_T_MIN) break;
    hits.push_back({g, alpha, sigma, vis, d, raw > SPLAT_ALPHA_MAX});
    T = next_T;
    last = i + 1;
  }
  return hits;
}

}  // namespace

RenderImages<double> reference_forward(const GaussianModel& m, const SplatCamera& cam) {
  const Prepared p = prepare(m, cam);
  const uint32_t W = cam.width, H = cam.height, C = m.channels;
  RenderImages<double> out;
  out.width = W;
  out.height = H;
  out.channels = C;
  out.image.assign(static_cast<size_t>(C) * W * H, 0.0);
  out.depth.assign(static_cast<size_t>(W) * H, 0.0);
  out.alpha.assign(static_cast<size_t>(W) * H, 0.0);
  out.last.assign(static_cast<size_t>(W) * H, 0);
  out.culled_nonfinite = p.culled_nonfinite;
  out.intersections = p.intersections;
  for (uint32_t py = 0; py < H; ++py)
    for (uint32_t px = 0; px < W; ++px) {
      const size_t pix = static_cast<size_t>(py) * W + px;
      double T = 1.0, depth_sum = 0.0;
      uint32_t last = 0;
      double Tw = 1.0;
      for (const Hit& h : walk_pixel(p, px, py, last, T)) {
        const double w = h.alpha * Tw;
        for (uint32_t c = 0; c < C; ++c) out.image[c * W * H + pix] += w * p.color[h.gaussian][c];
        depth_sum += w * p.proj[h.gaussian].depth;
        Tw *= 1.0 - h.alpha;
      }
      const double a = 1.0 - T;
      out.alpha[pix] = a;
      out.depth[pix] = a >= SPLAT_MIN_DEPTH_WEIGHT ? depth_sum / a : 0.0;
      out.last[pix] = last;
    }
  return out;
}

GaussianGrads<double> reference_backward(const GaussianModel& m, const SplatCamera& cam,
                                         const RenderGradInput& grad_out, bool depth_gradient_to_opacity) {
  const Prepared p = prepare(m, cam);
  const uint32_t W = cam.width, H = cam.height, C = m.channels, K = m.sh_coeffs();
  const size_t n = m.size(), npix = static_cast<size_t>(W) * H;
  if (grad_out.image.size() != C * npix)
    throw std::invalid_argument("reference_backward: grad image has " +
                                std::to_string(grad_out.image.size()) +
                                " values, expected C*H*W = " + std::to_string(C * npix));
  auto at = [](const std::vector<float>& v, size_t i) { return v.empty() ? 0.0 : static_cast<double>(v[i]); };

  std::vector<sm::ProjectedGrad> g2(n);
  for (auto& g : g2) {
    g.mean2d = glm::dvec2(0.0);
    g.conic = glm::dvec3(0.0);
    g.depth = 0.0;
    g.opacity = 0.0;
  }
  std::vector<std::vector<double>> gcolor(n, std::vector<double>(C, 0.0));

  for (uint32_t py = 0; py < H; ++py)
    for (uint32_t px = 0; px < W; ++px) {
      const size_t pix = static_cast<size_t>(py) * W + px;
      uint32_t last = 0;
      double T_final = 1.0;
      const std::vector<Hit> hits = walk_pixel(p, px, py, last, T_final);
      // Recompute the expected depth's numerator and the accumulated alpha as the forward did.
      double depth_sum = 0.0, Tw = 1.0;
      for (const Hit& h : hits) {
        depth_sum += h.alpha * Tw * p.proj[h.gaussian].depth;
        Tw *= 1.0 - h.alpha;
      }
      const double A = 1.0 - T_final;
      const bool has_depth = A >= SPLAT_MIN_DEPTH_WEIGHT;
      const double D = has_depth ? depth_sum / A : 0.0;
      const double dL_dN = has_depth ? at(grad_out.depth, pix) / A : 0.0;
      const double dL_dA = at(grad_out.alpha, pix) - (has_depth ? at(grad_out.depth, pix) * D / A : 0.0);
      std::vector<double> dL_dC(C);
      for (uint32_t c = 0; c < C; ++c) dL_dC[c] = grad_out.image[c * npix + pix];

      std::vector<double> acc_c(C, 0.0);
      double acc_z = 0.0, T = T_final;
      for (size_t k = hits.size(); k-- > 0;) {
        const Hit& h = hits[k];
        const uint32_t g = h.gaussian;
        const sm::Projected& pr = p.proj[g];
        const double one_minus = 1.0 - h.alpha;
        const double Ti = T / one_minus;
        const double w = h.alpha * Ti;
        double dL_dalpha_image = 0.0;
        for (uint32_t c = 0; c < C; ++c) {
          gcolor[g][c] += w * dL_dC[c];
          dL_dalpha_image += dL_dC[c] * (p.color[g][c] * Ti - acc_c[c] / one_minus);
          acc_c[c] += w * p.color[g][c];
        }
        g2[g].depth += w * dL_dN;
        const double dL_dalpha =
            dL_dalpha_image + dL_dN * (pr.depth * Ti - acc_z / one_minus) + dL_dA * T_final / one_minus;
        acc_z += w * pr.depth;
        T = Ti;
        if (h.clamped) continue;  // alpha = ALPHA_MAX does not depend on the Gaussian
        g2[g].opacity += (depth_gradient_to_opacity ? dL_dalpha : dL_dalpha_image) * h.vis;
        const double dL_dsigma = -dL_dalpha * h.alpha;
        g2[g].conic += dL_dsigma * glm::dvec3(0.5 * h.d.x * h.d.x, h.d.x * h.d.y, 0.5 * h.d.y * h.d.y);
        g2[g].mean2d += dL_dsigma * glm::dvec2(-(pr.conic.x * h.d.x + pr.conic.y * h.d.y),
                                               -(pr.conic.y * h.d.x + pr.conic.z * h.d.y));
      }
    }

  GaussianGrads<double> out;
  out.means.assign(n * 3, 0.0);
  out.log_scales.assign(n * 3, 0.0);
  out.quats.assign(n * 4, 0.0);
  out.opacity_logits.assign(n, 0.0);
  out.sh.assign(n * K * C, 0.0);
  out.means2d.assign(n * 2, 0.0);
  const sm::ViewGeometry v = view_geometry(cam);
  const glm::dvec3 centre = camera_centre(cam);
  for (size_t i = 0; i < n; ++i) {
    if (p.rect[i][0] >= p.rect[i][2]) continue;  // culled: no gradient
    const glm::dvec3 mean = vec3_at(m.means, i);
    const sm::ParamGrad pg = sm::project_gaussian_backward(v, mean, vec3_at(m.log_scales, i),
                                                           vec4_at(m.quats, i), m.opacity_logits[i], g2[i]);
    // SH: color = sum_k basis_k coeff_k + 0.5, clamped at 0.
    const glm::dvec3 ray = mean - centre;
    const glm::dvec3 dir = glm::normalize(ray);
    double basis[SPLAT_MAX_SH_COEFFS];
    sm::sh_basis(cam.sh_degree, dir, basis);
    double weights[SPLAT_MAX_SH_COEFFS] = {};
    for (uint32_t c = 0; c < C; ++c) {
      double sum = 0.5;
      for (uint32_t k = 0; k < K; ++k) sum += basis[k] * m.sh[(i * K + k) * C + c];
      if (sum < 0.0) continue;  // clamped channel
      for (uint32_t k = 0; k < K; ++k) {
        out.sh[(i * K + k) * C + c] = basis[k] * gcolor[i][c];
        weights[k] += gcolor[i][c] * m.sh[(i * K + k) * C + c];
      }
    }
    const glm::dvec3 ddir = sm::sh_basis_dir_grad(cam.sh_degree, dir, weights);
    const glm::dvec3 dray = (ddir - dir * glm::dot(dir, ddir)) / glm::length(ray);
    for (int a = 0; a < 3; ++a) {
      out.means[3 * i + a] = pg.mean[a] + dray[a];
      out.log_scales[3 * i + a] = pg.log_scale[a];
    }
    for (int a = 0; a < 4; ++a) out.quats[4 * i + a] = pg.quat[a];
    out.opacity_logits[i] = pg.opacity_logit;
    out.means2d[2 * i] = g2[i].mean2d.x;
    out.means2d[2 * i + 1] = g2[i].mean2d.y;
  }
  return out;
}

}  // namespace litgs::kernels
