// The splatting math, written once in the common subset of GLSL and C++/GLM: the kernels compile it in
// float32, the CPU reference (reference.cc) in double. Forward and backward of one Gaussian's projection,
// its spherical harmonics, and one pixel's alpha. Loops over buffers live in the kernels and the reference.
//
// Conventions: column-major matrices (GLSL and GLM agree); R_cam_world maps world to camera; quaternions
// are (w, x, y, z); pixel (i, j) has its centre at (i + 0.5, j + 0.5); conic (a, b, c) is the inverse 2D
// covariance [[a, b], [b, c]].
#ifndef LITGS_KERNELS_SPLAT_MATH_H
#define LITGS_KERNELS_SPLAT_MATH_H

#ifdef __cplusplus
#include <cmath>
#include <cstdint>
#include <glm/glm.hpp>

#include "kernels/splat/splat_shared.h"
namespace litgs::kernels::splat_math {
using namespace glm;
using real = double;
using vec2 = glm::dvec2;
using vec3 = glm::dvec3;
using vec4 = glm::dvec4;
using mat2 = glm::dmat2;
using mat3 = glm::dmat3;
using mat3x2 = glm::dmat3x2;  // 3 columns, 2 rows: the 2x3 Jacobian
using mat2x3 = glm::dmat2x3;
using uint = uint32_t;
#define SM_INOUT(T) T&
#define SM_OUT(T) T&
#define SM_OUT_ARRAY(T, name, n) T(&name)[n]
#define SM_IN_ARRAY(T, name, n) const T(&name)[n]
#define SM_FN inline
inline bool is_finite_real(real x) {
  return std::isfinite(x);
}
#else
#define real float
#define SM_INOUT(T) inout T
#define SM_OUT(T) out T
#define SM_OUT_ARRAY(T, name, n) out T name[n]
#define SM_IN_ARRAY(T, name, n) T name[n]
#define SM_FN
// Bitwise: fast-math may fold x == x, never an exponent test.
bool is_finite_real(float x) {
  return (floatBitsToUint(x) & 0x7f800000u) != 0x7f800000u;
}
#endif

SM_FN bool is_finite3(vec3 v) {
  return is_finite_real(v.x) && is_finite_real(v.y) && is_finite_real(v.z);
}
SM_FN bool is_finite4(vec4 v) {
  return is_finite3(vec3(v.x, v.y, v.z)) && is_finite_real(v.w);
}

// ---- Rotation ----

SM_FN mat3 rotation_from_unit_quat(vec4 q) {
  const real w = q.x, x = q.y, y = q.z, z = q.w;
  return mat3(
      real(1.0) - real(2.0) * (y * y + z * z), real(2.0) * (x * y + w * z), real(2.0) * (x * z - w * y),
      real(2.0) * (x * y - w * z), real(1.0) - real(2.0) * (x * x + z * z), real(2.0) * (y * z + w * x),
      real(2.0) * (x * z + w * y), real(2.0) * (y * z - w * x), real(1.0) - real(2.0) * (x * x + y * y));
}

// Unit quaternion, or (0, 0, 0, 0) below the norm floor, which rotation_from_unit_quat maps to identity.
SM_FN vec4 unit_quat(vec4 q) {
  const real n = length(q);
  return n > real(SPLAT_QUAT_NORM_FLOOR) ? q / n : vec4(real(0.0));
}

// dL/dq of the raw quaternion from dL/dR.
SM_FN vec4 quat_grad(vec4 q_raw, mat3 dR) {
  const real n = length(q_raw);
  if (!(n > real(SPLAT_QUAT_NORM_FLOOR))) return vec4(real(0.0));
  const vec4 q = q_raw / n;
  const real w = q.x, x = q.y, y = q.z, z = q.w;
  // dR[col][row]; R entries as in rotation_from_unit_quat.
  const real g00 = dR[0][0], g10 = dR[0][1], g20 = dR[0][2];
  const real g01 = dR[1][0], g11 = dR[1][1], g21 = dR[1][2];
  const real g02 = dR[2][0], g12 = dR[2][1], g22 = dR[2][2];
  vec4 dq;
  dq.x = real(2.0) * (z * (g10 - g01) + y * (g02 - g20) + x * (g21 - g12));
  dq.y = real(2.0) * (-real(2.0) * x * (g11 + g22) + y * (g10 + g01) + z * (g20 + g02) + w * (g21 - g12));
  dq.z = real(2.0) * (x * (g10 + g01) - real(2.0) * y * (g00 + g22) + z * (g21 + g12) + w * (g02 - g20));
  dq.w = real(2.0) * (x * (g20 + g02) + y * (g21 + g12) - real(2.0) * z * (g00 + g11) + w * (g10 - g01));
  // Through the normalization q = q_raw / |q_raw|.
  return (dq - q * dot(q, dq)) / n;
}

SM_FN vec3 clamped_scale(vec3 log_scale) {
  return exp(clamp(log_scale, vec3(real(SPLAT_LOG_SCALE_MIN)), vec3(real(SPLAT_LOG_SCALE_MAX))));
}

// ---- Spherical harmonics (real, 3DGS convention: color = sum_k basis_k c_k + 0.5, clamped at 0) ----

SM_FN void sh_basis(uint degree, vec3 d, SM_OUT_ARRAY(real, b, SPLAT_MAX_SH_COEFFS)) {
  for (uint k = 0u; k < uint(SPLAT_MAX_SH_COEFFS); ++k) b[k] = real(0.0);
  b[0] = real(0.28209479177387814);
  if (degree < 1u) return;
  const real x = d.x, y = d.y, z = d.z;
  b[1] = real(-0.4886025119029199) * y;
  b[2] = real(0.4886025119029199) * z;
  b[3] = real(-0.4886025119029199) * x;
  if (degree < 2u) return;
  const real xx = x * x, yy = y * y, zz = z * z;
  b[4] = real(1.0925484305920792) * x * y;
  b[5] = real(-1.0925484305920792) * y * z;
  b[6] = real(0.31539156525252005) * (real(2.0) * zz - xx - yy);
  b[7] = real(-1.0925484305920792) * x * z;
  b[8] = real(0.5462742152960396) * (xx - yy);
  if (degree < 3u) return;
  b[9] = real(-0.5900435899266435) * y * (real(3.0) * xx - yy);
  b[10] = real(2.890611442640554) * x * y * z;
  b[11] = real(-0.4570457994644658) * y * (real(4.0) * zz - xx - yy);
  b[12] = real(0.3731763325901154) * z * (real(2.0) * zz - real(3.0) * xx - real(3.0) * yy);
  b[13] = real(-0.4570457994644658) * x * (real(4.0) * zz - xx - yy);
  b[14] = real(1.445305721320277) * z * (xx - yy);
  b[15] = real(-0.5900435899266435) * x * (xx - real(3.0) * yy);
}

// d(sum_k g_k b_k)/d(direction) for per-coefficient weights g_k (the upstream gradient times coefficients).
SM_FN vec3 sh_basis_dir_grad(uint degree, vec3 d, SM_IN_ARRAY(real, g, SPLAT_MAX_SH_COEFFS)) {
  vec3 r = vec3(real(0.0));
  if (degree < 1u) return r;
  const real x = d.x, y = d.y, z = d.z;
  const real c1 = real(0.4886025119029199);
  r += vec3(real(0.0), -c1, real(0.0)) * g[1] + vec3(real(0.0), real(0.0), c1) * g[2] +
       vec3(-c1, real(0.0), real(0.0)) * g[3];
  if (degree < 2u) return r;
  const real xx = x * x, yy = y * y, zz = z * z;
  r += real(1.0925484305920792) * vec3(y, x, real(0.0)) * g[4];
  r += real(-1.0925484305920792) * vec3(real(0.0), z, y) * g[5];
  r += real(0.31539156525252005) * vec3(-real(2.0) * x, -real(2.0) * y, real(4.0) * z) * g[6];
  r += real(-1.0925484305920792) * vec3(z, real(0.0), x) * g[7];
  r += real(0.5462742152960396) * vec3(real(2.0) * x, -real(2.0) * y, real(0.0)) * g[8];
  if (degree < 3u) return r;
  r += real(-0.5900435899266435) * vec3(real(6.0) * x * y, real(3.0) * xx - real(3.0) * yy, real(0.0)) * g[9];
  r += real(2.890611442640554) * vec3(y * z, x * z, x * y) * g[10];
  r += real(-0.4570457994644658) *
       vec3(-real(2.0) * x * y, real(4.0) * zz - xx - real(3.0) * yy, real(8.0) * y * z) * g[11];
  r += real(0.3731763325901154) *
       vec3(-real(6.0) * x * z, -real(6.0) * y * z, real(6.0) * zz - real(3.0) * xx - real(3.0) * yy) * g[12];
  r += real(-0.4570457994644658) *
       vec3(real(4.0) * zz - real(3.0) * xx - yy, -real(2.0) * x * y, real(8.0) * x * z) * g[13];
  r += real(1.445305721320277) * vec3(real(2.0) * x * z, -real(2.0) * y * z, xx - yy) * g[14];
  r += real(-0.5900435899266435) * vec3(real(3.0) * xx - real(3.0) * yy, -real(6.0) * x * y, real(0.0)) *
       g[15];
  return r;
}

// ---- Projection ----

struct Projected {
  vec2 mean2d;   // pixels
  vec3 conic;    // inverse 2D covariance (a, b, c)
  real depth;    // camera z
  real opacity;  // sigmoid(logit)
  vec2 extent;   // half-extent in pixels along x and y where alpha falls to SPLAT_ALPHA_MIN
  bool finite;   // all parameters finite
  bool visible;  // in front of the near plane, non-degenerate, opaque enough and on the image
};

struct ViewGeometry {
  mat3 R;  // R_cam_world
  vec3 t;  // t_cam_world
  real fx, fy, cx, cy, near_m;
  real width, height;
};

// The EWA Jacobian of (u, v) w.r.t. the camera point, with x/z and y/z clamped to the frustum guard.
SM_FN mat3x2 projection_jacobian(ViewGeometry v, vec3 p, SM_OUT(bool) clamped_x, SM_OUT(bool) clamped_y) {
  const real lim_x_pos = (v.width - v.cx) / v.fx + real(SPLAT_FRUSTUM_GUARD - 1.0) * v.width / v.fx;
  const real lim_x_neg = v.cx / v.fx + real(SPLAT_FRUSTUM_GUARD - 1.0) * v.width / v.fx;
  const real lim_y_pos = (v.height - v.cy) / v.fy + real(SPLAT_FRUSTUM_GUARD - 1.0) * v.height / v.fy;
  const real lim_y_neg = v.cy / v.fy + real(SPLAT_FRUSTUM_GUARD - 1.0) * v.height / v.fy;
  const real rz = real(1.0) / p.z;
  const real tx = clamp(p.x * rz, -lim_x_neg, lim_x_pos);
  const real ty = clamp(p.y * rz, -lim_y_neg, lim_y_pos);
  clamped_x = tx != p.x * rz;
  clamped_y = ty != p.y * rz;
  // Columns: d/dx, d/dy, d/dz.
  return mat3x2(v.fx * rz, real(0.0), real(0.0), v.fy * rz, -v.fx * tx * rz, -v.fy * ty * rz);
}

SM_FN mat3 covariance_world(vec3 log_scale, vec4 quat_raw) {
  const mat3 R = rotation_from_unit_quat(unit_quat(quat_raw));
  const vec3 s = clamped_scale(log_scale);
  const mat3 M = mat3(R[0] * s.x, R[1] * s.y, R[2] * s.z);  // R * diag(s)
  return M * transpose(M);
}

SM_FN Projected project_gaussian(ViewGeometry v, vec3 mean, vec3 log_scale, vec4 quat_raw,
                                 real opacity_logit) {
  Projected o;
  o.mean2d = vec2(real(0.0));
  o.conic = vec3(real(0.0));
  o.depth = real(0.0);
  o.opacity = real(0.0);
  o.extent = vec2(real(0.0));
  o.visible = false;
  o.finite =
      is_finite3(mean) && is_finite3(log_scale) && is_finite4(quat_raw) && is_finite_real(opacity_logit);
  if (!o.finite) return o;
  const vec3 p = v.R * mean + v.t;
  o.depth = p.z;
  if (!(p.z >= v.near_m)) return o;
  bool cx, cy;
  const mat3x2 J = projection_jacobian(v, p, cx, cy);
  const mat3 cov3 = covariance_world(log_scale, quat_raw);
  const mat3x2 M = J * v.R;
  mat2 cov2 = M * cov3 * transpose(M);
  cov2[0][0] += real(SPLAT_LOW_PASS);
  cov2[1][1] += real(SPLAT_LOW_PASS);
  const real det = cov2[0][0] * cov2[1][1] - cov2[0][1] * cov2[1][0];
  if (!(det > real(0.0)) || !is_finite_real(det)) return o;
  o.conic = vec3(cov2[1][1] / det, -cov2[0][1] / det, cov2[0][0] / det);
  o.mean2d = vec2(v.fx * p.x / p.z + v.cx, v.fy * p.y / p.z + v.cy);
  o.opacity = real(1.0) / (real(1.0) + exp(-opacity_logit));
  if (!(o.opacity * real(255.0) > real(1.0))) return o;
  // Opacity-aware extent: alpha = opacity * exp(-d^2/2) reaches 1/255 at d^2 = 2 ln(255 opacity).
  const real k = sqrt(real(2.0) * log(o.opacity * real(255.0)));
  o.extent = vec2(k * sqrt(cov2[0][0]), k * sqrt(cov2[1][1]));
  if (!is_finite_real(o.mean2d.x) || !is_finite_real(o.mean2d.y) || !is_finite_real(o.extent.x) ||
      !is_finite_real(o.extent.y))
    return o;
  o.visible = o.mean2d.x + o.extent.x > real(0.0) && o.mean2d.x - o.extent.x < v.width &&
              o.mean2d.y + o.extent.y > real(0.0) && o.mean2d.y - o.extent.y < v.height;
  return o;
}

// Gradients of one Gaussian's projected quantities, as the per-pixel pass accumulates them.
struct ProjectedGrad {
  vec2 mean2d;
  vec3 conic;  // (dL/da, dL/db, dL/dc) with b entering sigma as b dx dy
  real depth;
  real opacity;
};

struct ParamGrad {
  vec3 mean;
  vec3 log_scale;
  vec4 quat;
  real opacity_logit;
};

SM_FN ParamGrad project_gaussian_backward(ViewGeometry v, vec3 mean, vec3 log_scale, vec4 quat_raw,
                                          real opacity_logit, ProjectedGrad g) {
  ParamGrad r;
  r.mean = vec3(real(0.0));
  r.log_scale = vec3(real(0.0));
  r.quat = vec4(real(0.0));
  const real opacity = real(1.0) / (real(1.0) + exp(-opacity_logit));
  r.opacity_logit = g.opacity * opacity * (real(1.0) - opacity);

  const vec3 p = v.R * mean + v.t;
  bool clamped_x, clamped_y;
  const mat3x2 J = projection_jacobian(v, p, clamped_x, clamped_y);
  const vec4 q = unit_quat(quat_raw);
  const mat3 Rq = rotation_from_unit_quat(q);
  const vec3 s = clamped_scale(log_scale);
  const mat3 Ms = mat3(Rq[0] * s.x, Rq[1] * s.y, Rq[2] * s.z);
  const mat3 cov3 = Ms * transpose(Ms);
  const mat3x2 M = J * v.R;
  mat2 cov2 = M * cov3 * transpose(M);
  cov2[0][0] += real(SPLAT_LOW_PASS);
  cov2[1][1] += real(SPLAT_LOW_PASS);
  const real det = cov2[0][0] * cov2[1][1] - cov2[0][1] * cov2[1][0];
  const mat2 conic = mat2(cov2[1][1] / det, -cov2[0][1] / det, -cov2[1][0] / det, cov2[0][0] / det);

  // conic -> cov2: dL/dCov = -Conic G Conic with G symmetric, off-diagonals carrying half of dL/db.
  const mat2 G = mat2(g.conic.x, real(0.5) * g.conic.y, real(0.5) * g.conic.y, g.conic.z);
  const mat2 dcov2 = -(conic * G * conic);
  // cov2 = M cov3 M^T: dL/dcov3 = M^T dcov2 M; dL/dM = 2 dcov2 M cov3 (both symmetric).
  const mat3 dcov3 = transpose(M) * dcov2 * M;
  const mat3x2 dM = real(2.0) * dcov2 * M * cov3;
  const mat3x2 dJ = dM * transpose(v.R);

  // cov3 = Ms Ms^T: dL/dMs = 2 dcov3 Ms; Ms = Rq diag(s).
  const mat3 dMs = real(2.0) * dcov3 * Ms;
  const vec3 ds = vec3(dot(Rq[0], dMs[0]), dot(Rq[1], dMs[1]), dot(Rq[2], dMs[2]));
  const vec3 ls_lo = vec3(real(SPLAT_LOG_SCALE_MIN)), ls_hi = vec3(real(SPLAT_LOG_SCALE_MAX));
  r.log_scale = ds * s;
  if (log_scale.x < ls_lo.x || log_scale.x > ls_hi.x) r.log_scale.x = real(0.0);
  if (log_scale.y < ls_lo.y || log_scale.y > ls_hi.y) r.log_scale.y = real(0.0);
  if (log_scale.z < ls_lo.z || log_scale.z > ls_hi.z) r.log_scale.z = real(0.0);
  const mat3 dRq = mat3(dMs[0] * s.x, dMs[1] * s.y, dMs[2] * s.z);
  r.quat = quat_grad(quat_raw, dRq);

  // Camera point: mean2d, depth and the Jacobian (through the clamped tx = x/z, ty = y/z).
  const real rz = real(1.0) / p.z, rz2 = rz * rz;
  vec3 dp = vec3(v.fx * rz * g.mean2d.x, v.fy * rz * g.mean2d.y,
                 -v.fx * p.x * rz2 * g.mean2d.x - v.fy * p.y * rz2 * g.mean2d.y + g.depth);
  // J = [[fx/z, 0, -fx tx/z], [0, fy/z, -fy ty/z]] with tx = x/z unless clamped.
  const real tx = -J[2][0] / (v.fx * rz);  // x/z, or its clamp
  const real ty = -J[2][1] / (v.fy * rz);
  const real dJ00 = dJ[0][0], dJ11 = dJ[1][1], dJ02 = dJ[2][0], dJ12 = dJ[2][1];
  // d/dz of each entry (tx fixed), then tx's own dependence on x and z when not clamped.
  dp.z += -v.fx * rz2 * dJ00 - v.fy * rz2 * dJ11 + v.fx * tx * rz2 * dJ02 + v.fy * ty * rz2 * dJ12;
  const real d_tx = -v.fx * rz * dJ02;
  const real d_ty = -v.fy * rz * dJ12;
  if (!clamped_x) {
    dp.x += d_tx * rz;
    dp.z += -d_tx * p.x * rz2;
  }
  if (!clamped_y) {
    dp.y += d_ty * rz;
    dp.z += -d_ty * p.y * rz2;
  }
  r.mean = transpose(v.R) * dp;
  return r;
}

// ---- One pixel ----

// sigma of the Gaussian at pixel offset d = pixel centre - mean2d.
SM_FN real gaussian_sigma(vec3 conic, vec2 d) {
  return real(0.5) * (conic.x * d.x * d.x + conic.z * d.y * d.y) + conic.y * d.x * d.y;
}

#ifdef __cplusplus
}  // namespace litgs::kernels::splat_math
#endif
#endif
