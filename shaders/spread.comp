#version 450
// LINEMOD spreading: OR of the labels in the T x T window below and right of each pixel.
#include "common.glsl"
layout(local_size_x = 64) in;
layout(std430, binding = 0) readonly buffer Src { uint8_t src[]; };
layout(std430, binding = 1) writeonly buffer Dst { uint8_t dst[]; };
layout(push_constant) uniform Push { int width; int height; int T; } pc;
void main() {
  int i = int(gl_GlobalInvocationID.x);
  if (i >= pc.width * pc.height) return;
  int y = i / pc.width, x = i - y * pc.width;
  uint acc = 0u;
  for (int dy = 0; dy < pc.T && y + dy < pc.height; ++dy)
    for (int dx = 0; dx < pc.T && x + dx < pc.width; ++dx) acc |= uint(src[i + dy * pc.width + dx]);
  dst[i] = uint8_t(acc);
}
