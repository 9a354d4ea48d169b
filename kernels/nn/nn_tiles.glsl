// The register tiles of nn_linear.comp and nn_matmul.comp. Where an invocation's tile lies in its output:
// tiles of `tile_rows` rows, the outputs' columns either interleaved over `lanes` neighbouring invocations,
// each taking `outputs` of them (column q of lane l: first + l + q lanes), or in quads, each invocation
// taking 4 neighbouring columns (so that a four-float texel holds them).

// Invocation e's first row and first column; its columns are first_column + q lanes.
void interleaved_tile(uint e, uint columns, uint tile_rows, uint lanes, uint outputs, out uint first_row,
                      out uint first_column) {
  const uint run = lanes * outputs;
  const uint runs = (columns + run - 1u) / run;
  const uint r = e / lanes;
  first_column = (r % runs) * run + e % lanes;
  first_row = (r / runs) * tile_rows;
}

// Invocation e's first row and first column; its columns are first_column .. first_column + 3.
void quad_tile(uint e, uint columns, uint tile_rows, out uint first_row, out uint first_column) {
  const uint quads = (columns + 3u) / 4u;
  first_column = (e % quads) * 4u;
  first_row = (e / quads) * tile_rows;
}

// s + a.x b.x + a.y b.y + a.z b.z + a.w b.w, added in that order (so that a quad path sums k in the same
// order as one float at a time).
float add_in_order(float s, vec4 a, vec4 b) {
  s += a.x * b.x;
  s += a.y * b.y;
  s += a.z * b.z;
  s += a.w * b.w;
  return s;
}
