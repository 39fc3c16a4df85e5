#version 450
// LINEMOD spreading: OR of the labels in the T x T window below and right of each pixel,
// as the OR of T row-spread pixels (spread_rows.comp) at and below it.
#include "common.glsl"
layout(local_size_x = 64) in;
layout(std430, binding = 0) readonly buffer Src { uint8_t rows[]; };
layout(std430, binding = 1) writeonly buffer Dst { uint8_t dst[]; };
layout(push_constant) uniform Push { int width; int height; int T; } pc;
void main() {
  int i = LINEAR_INVOCATION;
  if (i >= pc.width * pc.height) return;
  int y = i / pc.width;
  uint acc = 0u;
  for (int dy = 0; dy < pc.T && y + dy < pc.height; ++dy) acc |= uint(rows[i + dy * pc.width]);
  dst[i] = uint8_t(acc);
}
