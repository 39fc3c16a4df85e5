// Shared by the similarity kernels. The linear memories are read as a texel buffer of
// 16-byte texels: on llvmpipe (lavapipe) a texel fetch is one vector gather, while a
// storage-buffer load at a per-invocation offset becomes a branchy scalar loop over the
// lanes, once per 32-bit component. Each feature is a byte offset into the linear memories
// (position (0, 0) of its grid plane). Up to 63 features add up in packed bytes
// (63 * 4 < 256), then widen into packed 16-bit lanes (packed_scores.glsl).
#extension GL_EXT_samplerless_texture_functions : require
layout(binding = 0) uniform utextureBuffer memory;
layout(binding = 2) uniform itextureBuffer feature_offsets;  // r32i

// The 16 bytes at byte `q * 4 + s / 8` of the 32 in texels x, y: their words picked and
// funnel-shifted into alignment.
uvec4 alignBytes(uvec4 x, uvec4 y, uint q, uint s) {
  uvec4 a = q == 0u ? x : q == 1u ? uvec4(x.yzw, y.x) : q == 2u ? uvec4(x.zw, y.xy) : uvec4(x.w, y.xyz);
  uint e = q == 0u ? y.x : q == 1u ? y.y : q == 2u ? y.z : y.w;
  return s == 0u ? a : (a >> s) | (uvec4(a.yzw, e) << (32u - s));
}

// The 16 responses at byte offset `off`: two texels, aligned. The layouts' right and bottom
// margins keep the second texel inside the buffer.
uvec4 sixteenBytes(uint off) {
  int t = int(off >> 4);
  return alignBytes(texelFetch(memory, t), texelFetch(memory, t + 1), (off >> 2) & 3u, (off & 3u) * 8u);
}

// Widens packed byte sums into the packed 16-bit totals.
void widen(uvec4 acc, inout uvec4 lo, inout uvec4 hi) {
  lo += acc & 0x00FF00FFu;
  hi += (acc >> 8u) & 0x00FF00FFu;
}

// Sum of one template's feature responses at 16 consecutive cell positions of one row.
void scoreSixteen(int first, int count, int base, out uvec4 lo, out uvec4 hi) {
  lo = uvec4(0u);
  hi = uvec4(0u);
  int f = first;
  int end = first + count;
  while (f < end) {
    int chunk_end = min(f + 63, end);
    uvec4 acc = uvec4(0u);
    for (; f < chunk_end; ++f) acc += sixteenBytes(uint(texelFetch(feature_offsets, f).x + base));
    widen(acc, lo, hi);
  }
}

#include "packed_scores.glsl"

// Template header: first feature, feature count, first cell column, first cell row, raw
// threshold, then the coarse level's columns and rows of positions (match::coarseRange),
// unused.
layout(std430, binding = 1) readonly buffer Templates { int headers[]; };
const int HEADER_INTS = 8;
