#version 450
// 5x5 median of label values, replicated border (OpenCV's medianBlur(5) on 8 bits).
#include "common.glsl"
layout(local_size_x = 64) in;
layout(std430, binding = 0) readonly buffer Src { uint8_t src[]; };
layout(std430, binding = 1) writeonly buffer Dst { uint8_t dst[]; };
layout(push_constant) uniform Push { int width; int height; } pc;
void main() {
  int i = LINEAR_INVOCATION;
  if (i >= pc.width * pc.height) return;
  int y = i / pc.width, x = i - y * pc.width;
  // Labels take 9 values (0 and 1 << b): the median is the value where the running count
  // of a 9-bin histogram first exceeds 12.
  int counts[9] = int[](0, 0, 0, 0, 0, 0, 0, 0, 0);
  for (int dy = -2; dy <= 2; ++dy)
    for (int dx = -2; dx <= 2; ++dx) {
      uint v = uint(src[clampIndex(y + dy, pc.height) * pc.width + clampIndex(x + dx, pc.width)]);
      counts[v == 0u ? 0 : findLSB(v) + 1]++;
    }
  int seen = 0;
  uint median = 0u;
  for (int b = 0; b < 9; ++b) {
    seen += counts[b];
    if (seen > 12) { median = b == 0 ? 0u : 1u << (b - 1); break; }
  }
  dst[i] = uint8_t(median);
}
