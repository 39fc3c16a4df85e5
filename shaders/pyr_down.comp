#version 450
// Next pyramid level of the colour image: 5x5 binomial, every second pixel, reflected border.
// Pixels are packed BGRX words (common.glsl).
#include "common.glsl"
layout(local_size_x = kWorkgroupSize) in;
layout(binding = 0) uniform utextureBuffer src;  // a fetch is a gather on llvmpipe
layout(std430, binding = 1) writeonly buffer Dst { uint dst[]; };
layout(push_constant) uniform PyrDownPushBlock { PyrDownPush pc; };
const uint k[5] = uint[](1u, 4u, 6u, 4u, 1u);
void main() {
  int i = LINEAR_INVOCATION;
  int y, x0;
  if (!rowGroup(i, pc.width, pc.height, y, x0)) return;
  // kPixelGroup neighbouring output pixels of a row (common.glsl) share the 2 kPixelGroup + 3 source
  // columns of their windows. The weights sum to 256, so each sum of channel bytes fits the
  // 16-bit lanes of evenLanes / oddLanes: all channels at once, carry-free.
  int cols[2 * kPixelGroup + 3];
  [[unroll]] for (int t = 0; t < 2 * kPixelGroup + 3; ++t) cols[t] = reflect101Index(2 * x0 + t - 2, pc.src_width);
  uint even[kPixelGroup], odd[kPixelGroup];
  [[unroll]] for (int j = 0; j < kPixelGroup; ++j) even[j] = odd[j] = 0u;
  [[unroll]] for (int r = 0; r < 5; ++r) {
    int row = reflect101Index(2 * y + r - 2, pc.src_height) * pc.src_width;
    uint e[2 * kPixelGroup + 3], o[2 * kPixelGroup + 3];
    [[unroll]] for (int t = 0; t < 2 * kPixelGroup + 3; ++t) {
      uint v = texelFetch(src, row + cols[t]).x;
      e[t] = evenLanes(v);
      o[t] = oddLanes(v);
    }
    [[unroll]] for (int j = 0; j < kPixelGroup; ++j) {
      uint re = 0u, ro = 0u;
      [[unroll]] for (int t = 0; t < 5; ++t) {
        re += k[t] * e[2 * j + t];
        ro += k[t] * o[2 * j + t];
      }
      even[j] += k[r] * re;
      odd[j] += k[r] * ro;
    }
  }
  [[unroll]] for (int j = 0; j < kPixelGroup; ++j)
    if (x0 + j < pc.width) dst[y * pc.width + x0 + j] = fromLanes(even[j] + 0x00800080u, odd[j] + 0x00800080u, 8u);
}
