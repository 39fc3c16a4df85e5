#version 450
// Vertical pass of the 7x7 binomial blur, rounding back to 8 bits as OpenCV does; kPixelGroup
// neighbouring rows of one pixel column per invocation (common.glsl). In: the row pass's
// 16-bit lanes; out: packed BGRX words.
#include "common.glsl"
layout(local_size_x = kWorkgroupSize) in;
layout(binding = 0) uniform utextureBuffer src;  // R32G32 texels: a fetch is a gather on llvmpipe
layout(std430, binding = 1) writeonly buffer Dst { uint dst[]; };
layout(push_constant) uniform SizePushBlock { SizePush pc; };
const uint k[7] = uint[](8u, 28u, 56u, 72u, 56u, 28u, 8u);
void main() {
  int i = LINEAR_INVOCATION;
  int y0, x;
  if (!columnGroup(i, pc.width, pc.height, y0, x)) return;
  // Column sums reach 256 x 65280: 24 bits, so one channel per word here.
  uvec3 v[kPixelGroup + 6];
  [[unroll]] for (int t = 0; t < kPixelGroup + 6; ++t) {
    uvec2 s = texelFetch(src, clampIndex(y0 + t - 3, pc.height) * pc.width + x).xy;
    v[t] = uvec3(s.x & 0xFFFFu, s.y & 0xFFFFu, s.x >> 16u);
  }
  [[unroll]] for (int j = 0; j < kPixelGroup; ++j) {
    uvec3 acc = uvec3(0u);
    [[unroll]] for (int t = 0; t < 7; ++t) acc += k[t] * v[j + t];
    uvec3 c = (acc + 32768u) >> 16u;
    if (y0 + j < pc.height) dst[(y0 + j) * pc.width + x] = c.x | (c.y << 8u) | (c.z << 16u);
  }
}
