// One Adam step of one value (torch.optim.Adam's bias-corrected update), shared by adam.comp and
// gaussian_adam.comp so that the two stay the same arithmetic. Returns false, changing nothing, when the gradient,
// a moment or the new value is not finite (the caller counts the skip).
bool adam_step_value(AdamParams a, float lr, float g, inout float param, inout float m, inout float v) {
  const float m1 = a.beta1 * m + (1.0 - a.beta1) * g;
  const float v1 = a.beta2 * v + (1.0 - a.beta2) * (g * g);
  const float denom = sqrt(v1) / a.sqrt_bias_correction2 + a.eps;
  const float x = param - (lr / a.bias_correction1) * (m1 / denom);
  if (!finite_bits(g) || !finite_bits(m1) || !finite_bits(v1) || !finite_bits(x)) return false;
  m = m1;
  v = v1;
  param = x;
  return true;
}
