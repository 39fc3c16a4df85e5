#version 450
// Horizontal pass of the 7x7 binomial blur (8.8 fixed point, replicated border), kPixelGroup
// neighbouring pixels of a row per invocation (common.glsl). In: packed BGRX words. Out: the
// 16-bit sums of channels B, R (x) and G, X (y): the weights sum to 256, so all channels are
// summed at once in the 16-bit lanes of a word, carry-free.
#include "common.glsl"
layout(local_size_x = kWorkgroupSize) in;
layout(binding = 0) uniform utextureBuffer src;  // a fetch is a gather on llvmpipe
layout(std430, binding = 1) writeonly buffer Dst { uvec2 dst[]; };
layout(push_constant) uniform SizePushBlock { SizePush pc; };
const uint k[7] = uint[](8u, 28u, 56u, 72u, 56u, 28u, 8u);
void main() {
  int i = LINEAR_INVOCATION;
  int y, x0;
  if (!rowGroup(i, pc.width, pc.height, y, x0)) return;
  uint e[kPixelGroup + 6], o[kPixelGroup + 6];
  [[unroll]] for (int t = 0; t < kPixelGroup + 6; ++t) {
    uint v = texelFetch(src, y * pc.width + clampIndex(x0 + t - 3, pc.width)).x;
    e[t] = evenLanes(v);
    o[t] = oddLanes(v);
  }
  [[unroll]] for (int j = 0; j < kPixelGroup; ++j) {
    uvec2 acc = uvec2(0u);
    [[unroll]] for (int t = 0; t < 7; ++t) acc += k[t] * uvec2(e[j + t], o[j + t]);
    if (x0 + j < pc.width) dst[y * pc.width + x0 + j] = acc;
  }
}
