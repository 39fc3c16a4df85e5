#version 450
// First half of LINEMOD spreading: OR of the labels in the T pixels at and right of each
// pixel. spread.comp then ORs T of these downwards: T + T loads instead of T * T. GROUP
// neighbouring pixels of a row per invocation (common.glsl): T + GROUP - 1 loads for them.
#include "common.glsl"
layout(local_size_x = 64) in;
layout(std430, binding = 0) readonly buffer Src { uint8_t src[]; };
layout(std430, binding = 1) writeonly buffer Dst { uint8_t dst[]; };
layout(push_constant) uniform Push { int width; int height; int T; } pc;
void main() {
  int i = LINEAR_INVOCATION;
  int y, x0;
  if (!rowGroup(i, pc.width, pc.height, y, x0)) return;
  uint acc[GROUP];
  [[unroll]] for (int j = 0; j < GROUP; ++j) acc[j] = 0u;
  for (int t = 0; t < pc.T + GROUP - 1; ++t) {
    uint label = x0 + t < pc.width ? uint(src[y * pc.width + min(x0 + t, pc.width - 1)]) : 0u;
    [[unroll]] for (int j = 0; j < GROUP; ++j) acc[j] |= t >= j && t < j + pc.T ? label : 0u;
  }
  [[unroll]] for (int j = 0; j < GROUP; ++j)
    if (x0 + j < pc.width) dst[y * pc.width + x0 + j] = uint8_t(acc[j]);
}
