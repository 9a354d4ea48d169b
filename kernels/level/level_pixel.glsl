// The per-pixel factors of the level model (level_shared.h): r^2 of element e and the vignetting v.
float level_r2(uint e, LevelParams p) {
  const uint pixel = e % (p.width * p.height);
  const float dx = float(pixel % p.width) + 0.5 - p.cx;
  const float dy = float(pixel / p.width) + 0.5 - p.cy;
  return (dx * dx + dy * dy) * p.inv_r2_norm;
}

float level_vignetting(float r2, float k1, float k2) { return 1.0 + k1 * r2 + k2 * (r2 * r2); }
