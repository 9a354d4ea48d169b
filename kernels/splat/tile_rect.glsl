// A Gaussian's tile rectangle [x0, x1) x [y0, y1) in tile indices, stored as two words of 16-bit halves:
// 8 bytes per Gaussian instead of 16. Views are at most 16,384 pixels a side (SplatCamera::check): 1,024
// tiles, well within 16 bits.
uvec2 pack_tile_rect(uvec4 r) { return uvec2(r.x | (r.y << 16u), r.z | (r.w << 16u)); }

uvec4 unpack_tile_rect(uvec2 p) { return uvec4(p.x & 0xffffu, p.x >> 16u, p.y & 0xffffu, p.y >> 16u); }
