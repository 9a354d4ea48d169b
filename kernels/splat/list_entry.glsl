// Reading one entry of a tile's list, shared by rasterize_forward.comp and rasterize_backward.glsl. The
// including kernel declares the texel buffers isect_ids and isect_gaussian (usamplerBuffer), centres and
// conics (samplerBuffer, four floats per Gaussian) and colors (samplerBuffer, one float), as splat_shared.h
// describes them.

// Entry `i` of the sorted lists: its Gaussian g, footprint (mean2d, 1/255 half-extents), conic and opacity,
// depth and alpha_reach(opacity). The colour is load_entry_color's, for the entries a subgroup keeps.
void load_entry(uint i, out uint g, out vec4 mean_extent, out vec4 conic_opacity, out float depth,
                out float reach) {
  g = texelFetch(isect_gaussian, int(texelFetch(isect_ids, int(i)).x)).x;
  const vec4 centre_g = texelFetch(centres, int(g));  // mean2d, depth, opacity
  const vec4 conic_g = texelFetch(conics, int(g));    // conic, alpha_reach(opacity)
  mean_extent = vec4(centre_g.xy, alpha_extent(conic_g.xyz, conic_g.w));
  conic_opacity = vec4(conic_g.xyz, centre_g.w);
  depth = centre_g.z;
  reach = conic_g.w;
}

vec4 load_entry_color(uint g) {
  vec4 color = vec4(0.0);
  for (uint c = 0u; c < CHANNELS; ++c) color[c] = texelFetch(colors, int(g * CHANNELS + c)).x;
  return color;
}
