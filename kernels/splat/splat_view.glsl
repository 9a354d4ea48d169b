// The view of every splat kernel, from push constants, as the shared math's ViewGeometry. The rasterize
// kernels define SPLAT_RASTERIZE_PASS: their push constants add the pass's list segment (RasterizeParams).
#ifdef SPLAT_RASTERIZE_PASS
layout(push_constant) uniform Push {
  SplatView view;
  ListSegment segment;
};
#else
layout(push_constant) uniform Push { SplatView view; };
#endif

ViewGeometry view_geometry() {
  ViewGeometry v;
  v.R = mat3(view.rot[0], view.rot[1], view.rot[2], view.rot[3], view.rot[4], view.rot[5], view.rot[6],
             view.rot[7], view.rot[8]);
  v.t = vec3(view.trans[0], view.trans[1], view.trans[2]);
  v.fx = view.fx;
  v.fy = view.fy;
  v.cx = view.cx;
  v.cy = view.cy;
  v.near_m = view.near_m;
  v.width = float(view.width);
  v.height = float(view.height);
  return v;
}

vec3 camera_centre() {
  const ViewGeometry v = view_geometry();
  return -(transpose(v.R) * v.t);
}

// Element i of a one-float texel buffer, and elements 3i .. 3i + 2 (a [N][3] array).
float fetch1(samplerBuffer b, uint i) { return texelFetch(b, int(i)).x; }
vec3 fetch3(samplerBuffer b, uint i) { return vec3(fetch1(b, 3u * i), fetch1(b, 3u * i + 1u), fetch1(b, 3u * i + 2u)); }

// Model channel count (1 thermal, 3 RGB): a specialization constant so buffers and loops fit the model.
layout(constant_id = 1) const uint CHANNELS = 1;
// Gradient values per Gaussian (or intersection) between the per-pixel and per-Gaussian passes.
const uint GRAD2D_STRIDE = SPLAT_GRAD2D_FIXED + CHANNELS;
