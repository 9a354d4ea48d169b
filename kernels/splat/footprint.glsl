// A Gaussian's footprint in a tile, for skipping whole subgroups of pixels at once.

// ln(max(255 opacity, 1)): opacity * exp(-sigma) >= 1/255 where sigma is at most this. project.comp stores
// it beside the conic, so that the rasterize kernels take no logarithm per list entry.
float alpha_reach(float opacity) { return log(max(opacity * 255.0, 1.0)); }

// Half-extents (x, y) of the region where opacity * exp(-sigma) >= 1/255, from the conic and
// alpha_reach(opacity): the same axis-aligned box project_gaussian computes from the covariance.
vec2 alpha_extent(vec3 conic, float reach) {
  const float det = conic.x * conic.z - conic.y * conic.y;
  const float k2 = 2.0 * reach;
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

#ifdef SPLAT_RASTERIZE_PASS
// Pixels per invocation, 8 (a 2x4 block) or 1, and the workgroup size (8x4 or 16x16 invocations per 16x16
// tile): specialization constants (splat_shared.h). On a CPU device every subgroup reads its tile's whole
// list, so eight pixels per invocation mean fewer reads, tests, butterfly sums and atomic adds per pixel
// (docs/design.md, how the rasterizer works); a GPU wants the 256 invocations.
#if SPLAT_TILE_SIZE != 16
#error "block_origin() numbers the pixels of a 16x16 tile"
#endif
layout(constant_id = SPLAT_SPEC_PIXEL_BLOCK) const uint PIXEL_BLOCK = 8u;
layout(local_size_x = 8, local_size_y = 4) in;
layout(local_size_x_id = SPLAT_SPEC_GROUP_X, local_size_y_id = SPLAT_SPEC_GROUP_Y) in;
const uint GROUP_INVOCATIONS = gl_WorkGroupSize.x * gl_WorkGroupSize.y;

// The origin of this invocation's block of pixels (PIXEL_BLOCK 8: 2x4 pixels, 1: one pixel), invocations in
// Z (Morton) order, so that a subgroup covers a compact region (8 lanes: 8x8 pixels with 2x4 blocks, 4x2
// with one pixel; 32 lanes: the tile, or 8x4) and skips the footprints that miss it.
uvec2 block_origin() {
  const uint i = gl_LocalInvocationIndex;
  const uvec2 tile_origin = gl_WorkGroupID.xy * uint(SPLAT_TILE_SIZE);
  if (PIXEL_BLOCK == 1u) {
    const uint x = (i & 1u) | ((i >> 1u) & 2u) | ((i >> 2u) & 4u) | ((i >> 3u) & 8u);
    const uint y = ((i >> 1u) & 1u) | ((i >> 2u) & 2u) | ((i >> 3u) & 4u) | ((i >> 4u) & 8u);
    return tile_origin + uvec2(x, y);
  }
  const uint x = (i & 1u) | ((i >> 1u) & 2u) | ((i >> 2u) & 4u);
  const uint y = ((i >> 1u) & 1u) | ((i >> 2u) & 2u);
  return tile_origin + uvec2(2u * x, 4u * y);
}

// Pixel (dx, dy) of the invocation's block, or one outside every image when the block has one pixel.
uvec2 block_pixel(uvec2 origin, uint dx, uint dy) {
  return PIXEL_BLOCK == 8u || (dx == 0u && dy == 0u) ? origin + uvec2(dx, dy) : uvec2(0xffffffffu);
}

// The subgroup's lanes that exist: a device whose subgroups are wider than the workgroup (64-wide AMD waves)
// runs it as one partial subgroup, whose chunks of list entries and butterfly sums must not reach past it.
uint subgroup_lanes() { return min(gl_SubgroupSize, GROUP_INVOCATIONS); }

// The 32-bit words of a ballot that hold the subgroup's lanes: 1 with 2x4 pixels per invocation, known when
// the pipeline is built (a CPU driver would otherwise run the word loop's body once more, masked).
uint ballot_words() { return GROUP_INVOCATIONS <= 32u ? 1u : (subgroup_lanes() + 31u) / 32u; }
#endif

// sigma along the edge x = dx (relative to the mean) of a box, at its smallest: dy = -(b / c) dx clamped
// to [dy_lo, dy_hi] (sigma is a convex quadratic). Lowered by 1e-5 of the terms' magnitudes, so that float
// rounding here can never exceed the rounding of the walk's own sigma at a pixel centre on the edge.
float edge_min_sigma(float a, float b, float c, float b_over_c, float dx, float dy_lo, float dy_hi) {
  const float dy = clamp(-b_over_c * dx, dy_lo, dy_hi);
  const float xx = 0.5 * a * dx * dx, yy = 0.5 * c * dy * dy, xy = b * dx * dy;
  return xx + yy + xy - 1e-5 * (xx + yy + abs(xy));
}

// Whether the Gaussian's alpha can reach 1/255 at any pixel centre in the box [lo, hi]: its smallest sigma
// over the box (0 with the mean inside, else the least over the four edges) against ln(255 opacity), with
// 0.02 of margin for the rounding of exp, log and the walk's pixel offsets (sigma changes by under 1e-3 for
// a 1e-4 pixel offset within the footprint). Conservative: true for a conic that is not positive definite.
// An entry this rejects adds exactly nothing in the walk (alpha < 1/255 at every pixel of the box).
bool footprint_touches_box(vec4 mean_extent, vec4 conic_opacity, float reach, vec2 lo, vec2 hi) {
  const float a = conic_opacity.x, b = conic_opacity.y, c = conic_opacity.z;
  const vec2 d_lo = lo - mean_extent.xy, d_hi = hi - mean_extent.xy;
  const bool definite = a > 0.0 && c > 0.0 && a * c - b * b > 0.0;
  const bool inside = all(lessThanEqual(d_lo, vec2(0.0))) && all(greaterThanEqual(d_hi, vec2(0.0)));
  const float a_s = definite ? a : 1.0, c_s = definite ? c : 1.0;  // no division by 0 when not used
  const float b_over_c = b / c_s, b_over_a = b / a_s;
  const float least = min(min(edge_min_sigma(a_s, b, c_s, b_over_c, d_lo.x, d_lo.y, d_hi.y),
                              edge_min_sigma(a_s, b, c_s, b_over_c, d_hi.x, d_lo.y, d_hi.y)),
                          min(edge_min_sigma(c_s, b, a_s, b_over_a, d_lo.y, d_lo.x, d_hi.x),
                              edge_min_sigma(c_s, b, a_s, b_over_a, d_hi.y, d_lo.x, d_hi.x)));
  // alpha_reach(opacity): below opacity 1/255 nothing hits anyway, and the limit 0.02 keeps the entry only
  // where sigma <= 0.02.
  const float limit = reach + 0.02;
  return !definite || inside || !(least > limit);
}
