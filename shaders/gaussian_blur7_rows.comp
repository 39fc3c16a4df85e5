#version 450
// Horizontal pass of the 7x7 binomial blur (8.8 fixed point, replicated border), GROUP
// neighbouring pixels of a row per invocation (common.glsl).
#include "common.glsl"
layout(local_size_x = 64) in;
layout(std430, binding = 0) readonly buffer Src { uint8_t src[]; };
layout(std430, binding = 1) writeonly buffer Dst { uint16_t dst[]; };
layout(push_constant) uniform Push { int width; int height; } pc;
const uint k[7] = uint[](8u, 28u, 56u, 72u, 56u, 28u, 8u);
void main() {
  int i = LINEAR_INVOCATION;
  int y, x0;
  if (!rowGroup(i, pc.width, pc.height, y, x0)) return;
  [[unroll]] for (int ch = 0; ch < 3; ++ch) {
    uint v[GROUP + 6];
    [[unroll]] for (int t = 0; t < GROUP + 6; ++t)
      v[t] = uint(src[(y * pc.width + clampIndex(x0 + t - 3, pc.width)) * 3 + ch]);
    [[unroll]] for (int j = 0; j < GROUP; ++j) {
      uint acc = 0u;
      [[unroll]] for (int t = 0; t < 7; ++t) acc += k[t] * v[j + t];
      if (x0 + j < pc.width) dst[(y * pc.width + x0 + j) * 3 + ch] = uint16_t(acc);
    }
  }
}
