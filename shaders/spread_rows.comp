#version 450
// First half of LINEMOD spreading: OR of the labels in the T pixels at and right of each
// pixel. spread_cols.comp then ORs T of these downwards: T + T loads instead of T * T.
#include "common.glsl"
layout(local_size_x = 64) in;
layout(std430, binding = 0) readonly buffer Src { uint8_t src[]; };
layout(std430, binding = 1) writeonly buffer Dst { uint8_t dst[]; };
layout(push_constant) uniform Push { int width; int height; int T; } pc;
void main() {
  int i = LINEAR_INVOCATION;
  if (i >= pc.width * pc.height) return;
  int x = i % pc.width;
  uint acc = 0u;
  for (int dx = 0; dx < pc.T && x + dx < pc.width; ++dx) acc |= uint(src[i + dx]);
  dst[i] = uint8_t(acc);
}
