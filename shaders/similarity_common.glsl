// Shared by the similarity kernels. The linear memories are read as a texel buffer of
// 16-byte texels: on llvmpipe (lavapipe) a texel fetch is eight 16-byte loads and a
// transpose, while a storage-buffer load at a per-invocation offset becomes a branchy
// scalar loop over the lanes, once per 32-bit component. The memories hold a nibble per
// cell (responses are 0..4), 32 cells a texel: the fetches, not the arithmetic, set the
// pace, and nibbles halve them. Each feature is a cell (nibble) offset into the linear
// memories (position (0, 0) of its grid plane). Up to 63 features add up in packed bytes,
// then widen into packed 16-bit lanes (packed_scores.glsl).
#extension GL_EXT_samplerless_texture_functions : require
layout(binding = 0) uniform utextureBuffer memory;
layout(binding = 2) uniform itextureBuffer feature_offsets;  // r32i

// Word q (0..3) of the four from w0 on.
uint wordAt(uint w0, uint w1, uint w2, uint w3, uint q) { return q == 0u ? w0 : q == 1u ? w1 : q == 2u ? w2 : w3; }

// The 16 cells of a block, 64 bits from bit s (a multiple of 4) of word a on (b and c the
// next words), as byte sums to add: cells 0, 2, .., 14 in x and y, cells 1, 3, .., 15 in z
// and w. Up to 63 features add up without a carry (63 * 4 < 256).
uvec4 nibbleBlock(uint a, uint b, uint c, uint s) {
  uvec2 w = s == 0u ? uvec2(a, b) : uvec2((a >> s) | (b << (32u - s)), (b >> s) | (c << (32u - s)));
  return uvec4(w & 0x0F0F0F0Fu, (w >> 4u) & 0x0F0F0F0Fu);
}

// Byte sums as nibbleBlock leaves them added into the packed 16-bit totals of
// packed_scores.glsl (lo: cells 4j and 4j + 2 in word j, hi: 4j + 1 and 4j + 3).
uint spreadBytes(uint v) { return (v & 0xFFu) | ((v & 0xFF00u) << 8u); }
void widenSplit(uvec4 acc, inout uvec4 lo, inout uvec4 hi) {
  lo += uvec4(spreadBytes(acc.x), spreadBytes(acc.x >> 16u), spreadBytes(acc.y), spreadBytes(acc.y >> 16u));
  hi += uvec4(spreadBytes(acc.z), spreadBytes(acc.z >> 16u), spreadBytes(acc.w), spreadBytes(acc.w >> 16u));
}

#include "packed_scores.glsl"

// Template header: first feature, feature count, first cell column, first cell row, raw
// threshold, then the coarse level's columns and rows of positions (match::coarseRange),
// unused.
layout(std430, binding = 1) readonly buffer Templates { int headers[]; };
const int HEADER_INTS = 8;
