#version 450
// Horizontal pass of the 7x7 binomial blur (8.8 fixed point, replicated border).
#include "common.glsl"
layout(local_size_x = 64) in;
layout(std430, binding = 0) readonly buffer Src { uint8_t src[]; };
layout(std430, binding = 1) writeonly buffer Dst { uint16_t dst[]; };
layout(push_constant) uniform Push { int width; int height; } pc;
const uint k[7] = uint[](8u, 28u, 56u, 72u, 56u, 28u, 8u);
void main() {
  int i = LINEAR_INVOCATION;
  if (i >= pc.width * pc.height) return;
  int y = i / pc.width, x = i - y * pc.width;
  for (int ch = 0; ch < 3; ++ch) {
    uint acc = 0u;
    for (int t = 0; t < 7; ++t) acc += k[t] * uint(src[(y * pc.width + clampIndex(x + t - 3, pc.width)) * 3 + ch]);
    dst[i * 3 + ch] = uint16_t(acc);
  }
}
