// Gradients of one Gaussian's raw parameters from those of its projected quantities and colour (the rows
// rasterize_backward leaves, [N][GRAD2D_STRIDE]), shared by project_backward.comp, which stores them, and
// optim/gaussian_adam.comp, which steps the parameters with them at once. The includer defines CHANNELS,
// GRAD2D_STRIDE, unpack_tile_rect (splat/tile_rect.glsl) with the rects binding, and the reads:
//   vec3 param_mean(uint i), vec3 param_log_scale(uint i), vec4 param_quat(uint i),
//   float param_logit(uint i), float param_sh(uint j), float grad2d_value(uint j).

struct ParamGradients {
  vec3 mean;
  vec3 log_scale;
  vec4 quat;
  float logit;
  // The SH gradient is basis[k] * color[c] for coefficient k of channel c (0 where the colour was clamped).
  float basis[SPLAT_MAX_SH_COEFFS];
  vec4 color;
};

// A culled Gaussian (empty tile rectangle) gets zero gradients.
ParamGradients param_gradients(uint i, ViewGeometry geometry, uint sh_degree, uint sh_coeffs) {
  ParamGradients grads;
  grads.mean = vec3(0.0);
  grads.log_scale = vec3(0.0);
  grads.quat = vec4(0.0);
  grads.logit = 0.0;
  grads.color = vec4(0.0);
  for (uint k = 0u; k < uint(SPLAT_MAX_SH_COEFFS); ++k) grads.basis[k] = 0.0;
  const uvec4 r = unpack_tile_rect(rects[i]);
  if (r.z <= r.x) return grads;
  const uint K = sh_coeffs;
  const uint base = i * GRAD2D_STRIDE;
  ProjectedGrad pg;
  pg.mean2d = vec2(grad2d_value(base), grad2d_value(base + 1));
  pg.conic = vec3(grad2d_value(base + 2), grad2d_value(base + 3), grad2d_value(base + 4));
  pg.opacity = grad2d_value(base + 5);
  pg.depth = grad2d_value(base + 6);

  const vec3 mean = param_mean(i);
  const ParamGrad p =
      project_gaussian_backward(geometry, mean, param_log_scale(i), param_quat(i), param_logit(i), pg);

  // Colour = sum_k basis_k c_k + 0.5, clamped at 0; its direction depends on the mean.
  const vec3 ray = mean - (-(transpose(geometry.R) * geometry.t));
  const vec3 dir = normalize(ray);
  sh_basis(sh_degree, dir, grads.basis);
  float weights[SPLAT_MAX_SH_COEFFS];
  for (uint k = 0u; k < uint(SPLAT_MAX_SH_COEFFS); ++k) weights[k] = 0.0;
  // The basis is 0 beyond the active degree: those coefficients add nothing (to finite sums).
  const uint active_coeffs = min(K, (sh_degree + 1u) * (sh_degree + 1u));
  for (uint c = 0u; c < CHANNELS; ++c) {
    const float g_color = grad2d_value(base + SPLAT_GRAD2D_FIXED + c);
    float sum = 0.5;
    for (uint k = 0u; k < active_coeffs; ++k) sum += grads.basis[k] * param_sh((i * K + k) * CHANNELS + c);
    const bool clamped = sum < 0.0;
    grads.color[c] = clamped ? 0.0 : g_color;
    if (!clamped)
      for (uint k = 0u; k < active_coeffs; ++k) weights[k] += g_color * param_sh((i * K + k) * CHANNELS + c);
  }
  const vec3 ddir = sh_basis_dir_grad(sh_degree, dir, weights);
  const vec3 dray = (ddir - dir * dot(dir, ddir)) / length(ray);
  grads.mean = p.mean + dray;
  grads.log_scale = p.log_scale;
  grads.quat = p.quat;
  grads.logit = p.opacity_logit;
  return grads;
}
