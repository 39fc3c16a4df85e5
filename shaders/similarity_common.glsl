// Shared by the similarity kernels. The linear memories are read as a texel buffer of
// 16-byte texels: on llvmpipe (lavapipe) a texel fetch is eight 16-byte loads and a
// transpose, while a storage-buffer load at a per-invocation offset becomes a branchy
// scalar loop over the lanes, once per 32-bit component. Each feature is a byte offset into the linear memories
// (position (0, 0) of its grid plane). Up to 63 features add up in packed bytes
// (63 * 4 < 256), then widen into packed 16-bit lanes (packed_scores.glsl).
#extension GL_EXT_samplerless_texture_functions : require
layout(binding = 0) uniform utextureBuffer memory;
layout(binding = 2) uniform itextureBuffer feature_offsets;  // r32i

// The 16 bytes at byte `q * 4 + s / 8` of the 32 in texels x, y: their words picked and
// funnel-shifted into alignment. A feature's 16 responses at byte offset `off` are those
// of texels off / 16 and off / 16 + 1, so a row of L blocks of 16 positions takes L + 1
// texels; the layouts' right and bottom margins keep the last one inside the buffer.
uvec4 alignBytes(uvec4 x, uvec4 y, uint q, uint s) {
  uvec4 a = q == 0u ? x : q == 1u ? uvec4(x.yzw, y.x) : q == 2u ? uvec4(x.zw, y.xy) : uvec4(x.w, y.xyz);
  uint e = q == 0u ? y.x : q == 1u ? y.y : q == 2u ? y.z : y.w;
  return s == 0u ? a : (a >> s) | (uvec4(a.yzw, e) << (32u - s));
}

// Widens packed byte sums into the packed 16-bit totals.
void widen(uvec4 acc, inout uvec4 lo, inout uvec4 hi) {
  lo += acc & 0x00FF00FFu;
  hi += (acc >> 8u) & 0x00FF00FFu;
}

#include "packed_scores.glsl"

// Template header: first feature, feature count, first cell column, first cell row, raw
// threshold, then the coarse level's columns and rows of positions (match::coarseRange),
// unused.
layout(std430, binding = 1) readonly buffer Templates { int headers[]; };
const int HEADER_INTS = 8;
