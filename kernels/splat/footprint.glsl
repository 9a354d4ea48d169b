// A Gaussian's footprint in a tile, for skipping whole subgroups of pixels at once.

// Half-extents (x, y) of the region where opacity * exp(-sigma) >= 1/255, from the conic: the same
// axis-aligned box project_gaussian computes from the covariance.
vec2 alpha_extent(vec3 conic, float opacity) {
  const float det = conic.x * conic.z - conic.y * conic.y;
  const float k2 = 2.0 * log(max(opacity * 255.0, 1.0));
  return sqrt(max(k2 * vec2(conic.z, conic.x) / det, vec2(0.0)));
}

// Whether the footprint (mean.xy, extent.zw) reaches the box [lo, hi] of pixel centres, with half a pixel
// of margin so that float rounding never drops a contribution the reference keeps.
bool footprint_reaches(vec4 mean_extent, vec2 lo, vec2 hi) {
  const vec2 nearest = clamp(mean_extent.xy, lo, hi);
  return all(lessThanEqual(abs(nearest - mean_extent.xy), mean_extent.zw + 0.5));
}

// Beyond this sigma alpha is below 1/255 for any opacity <= 1 (ln 255 = 5.5): clamping sigma there changes
// no result and keeps exp() away from denormals, which are very slow on CPUs.
const float SIGMA_CUTOFF = 30.0;
