#version 450
// Vertical pass of the 7x7 binomial blur, rounding back to 8 bits as OpenCV does.
#include "common.glsl"
layout(local_size_x = 64) in;
layout(std430, binding = 0) readonly buffer Src { uint16_t src[]; };
layout(std430, binding = 1) writeonly buffer Dst { uint8_t dst[]; };
layout(push_constant) uniform Push { int width; int height; } pc;
const uint k[7] = uint[](8u, 28u, 56u, 72u, 56u, 28u, 8u);
void main() {
  int i = LINEAR_INVOCATION;
  if (i >= pc.width * pc.height * 3) return;
  int row = pc.width * 3;
  int y = i / row, xc = i - y * row;
  uint acc = 0u;
  for (int t = 0; t < 7; ++t) acc += k[t] * uint(src[clampIndex(y + t - 3, pc.height) * row + xc]);
  dst[i] = uint8_t((acc + 32768u) >> 16);
}
