#version 450
// Vertical pass of the 7x7 binomial blur, rounding back to 8 bits as OpenCV does; GROUP
// neighbouring rows of one channel column per invocation (common.glsl).
#include "common.glsl"
layout(local_size_x = 64) in;
layout(std430, binding = 0) readonly buffer Src { uint16_t src[]; };
layout(std430, binding = 1) writeonly buffer Dst { uint8_t dst[]; };
layout(push_constant) uniform Push { int width; int height; } pc;
const uint k[7] = uint[](8u, 28u, 56u, 72u, 56u, 28u, 8u);
void main() {
  int i = LINEAR_INVOCATION;
  int row = pc.width * 3;
  int y0, xc;
  if (!columnGroup(i, row, pc.height, y0, xc)) return;
  uint v[GROUP + 6];
  [[unroll]] for (int t = 0; t < GROUP + 6; ++t) v[t] = uint(src[clampIndex(y0 + t - 3, pc.height) * row + xc]);
  [[unroll]] for (int j = 0; j < GROUP; ++j) {
    uint acc = 0u;
    [[unroll]] for (int t = 0; t < 7; ++t) acc += k[t] * v[j + t];
    if (y0 + j < pc.height) dst[(y0 + j) * row + xc] = uint8_t((acc + 32768u) >> 16);
  }
}
