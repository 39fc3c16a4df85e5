#version 450
// Next pyramid level of the colour image: 5x5 binomial, every second pixel, reflected border.
#include "common.glsl"
layout(local_size_x = 64) in;
layout(std430, binding = 0) readonly buffer Src { uint8_t src[]; };
layout(std430, binding = 1) writeonly buffer Dst { uint8_t dst[]; };
layout(push_constant) uniform Push { int src_width; int src_height; int width; int height; } pc;
const int k[5] = int[](1, 4, 6, 4, 1);
void main() {
  int i = LINEAR_INVOCATION;
  int y, x0;
  if (!rowGroup(i, pc.width, pc.height, y, x0)) return;
  // GROUP neighbouring output pixels of a row (common.glsl) share the 2 GROUP + 3 source
  // columns of their windows.
  int cols[2 * GROUP + 3];
  [[unroll]] for (int t = 0; t < 2 * GROUP + 3; ++t) cols[t] = reflect101Index(2 * x0 + t - 2, pc.src_width);
  int rows[5];
  [[unroll]] for (int r = 0; r < 5; ++r) rows[r] = reflect101Index(2 * y + r - 2, pc.src_height) * pc.src_width;
  [[unroll]] for (int ch = 0; ch < 3; ++ch) {
    int acc[GROUP];
    [[unroll]] for (int j = 0; j < GROUP; ++j) acc[j] = 0;
    [[unroll]] for (int r = 0; r < 5; ++r) {
      int v[2 * GROUP + 3];
      [[unroll]] for (int t = 0; t < 2 * GROUP + 3; ++t) v[t] = int(src[(rows[r] + cols[t]) * 3 + ch]);
      [[unroll]] for (int j = 0; j < GROUP; ++j) {
        int racc = 0;
        [[unroll]] for (int t = 0; t < 5; ++t) racc += k[t] * v[2 * j + t];
        acc[j] += k[r] * racc;
      }
    }
    [[unroll]] for (int j = 0; j < GROUP; ++j)
      if (x0 + j < pc.width) dst[(y * pc.width + x0 + j) * 3 + ch] = uint8_t((acc[j] + 128) >> 8);
  }
}
