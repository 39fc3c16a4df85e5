#version 450
// LINEMOD spreading: OR of the labels in the T x T window below and right of each pixel,
// as the OR of T row-spread pixels (spread_rows.comp) at and below it. GROUP neighbouring
// rows of one column per invocation (common.glsl): T + GROUP - 1 loads for them.
#include "common.glsl"
layout(local_size_x = 64) in;
layout(std430, binding = 0) readonly buffer Src { uint8_t rows[]; };
layout(std430, binding = 1) writeonly buffer Dst { uint8_t dst[]; };
layout(push_constant) uniform Push { int width; int height; int T; } pc;
void main() {
  int i = LINEAR_INVOCATION;
  int y0, x;
  if (!columnGroup(i, pc.width, pc.height, y0, x)) return;
  uint acc[GROUP];
  [[unroll]] for (int j = 0; j < GROUP; ++j) acc[j] = 0u;
  for (int t = 0; t < pc.T + GROUP - 1; ++t) {
    uint label = y0 + t < pc.height ? uint(rows[min(y0 + t, pc.height - 1) * pc.width + x]) : 0u;
    [[unroll]] for (int j = 0; j < GROUP; ++j) acc[j] |= t >= j && t < j + pc.T ? label : 0u;
  }
  [[unroll]] for (int j = 0; j < GROUP; ++j)
    if (y0 + j < pc.height) dst[(y0 + j) * pc.width + x] = uint8_t(acc[j]);
}
