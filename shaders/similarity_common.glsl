// Shared by the similarity kernels. The linear memories are read as a texel buffer of
// 16-byte texels: on llvmpipe (lavapipe) a texel fetch is eight 16-byte loads and a
// transpose, while a storage-buffer load at a per-invocation offset becomes a branchy
// scalar loop over the lanes, once per 32-bit component. The memories hold a nibble per
// cell (responses are 0..4), 32 cells a texel: the fetches, not the arithmetic, set the
// pace, and nibbles halve them. Each feature is a cell (nibble) offset into the linear
// memories (position (0, 0) of its grid plane). Up to 63 features add up in packed bytes,
// then widen into packed 16-bit lanes (packed_scores.glsl).
#extension GL_EXT_samplerless_texture_functions : require
#include "gpu/kernel_interface.h"
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

// Texels that hold `cells` consecutive cells starting at any of a texel's 32 nibbles.
#define TEXELS_FOR(cells) (((cells) + 30) / 32 + 1)

// Texel, word q in it and bit s in that word of nibble offset `off`. Strides are multiples
// of 32 cells, so every row of a plane has the same q and s.
void nibbleAddress(uint off, out int texel, out uint q, out uint s) {
  texel = int(off >> 5u);
  q = (off >> 3u) & 3u;
  s = (off & 7u) * 4u;
}

// Adds SPAN blocks of 16 cells of one row, read from the TEXELS texels from `texel` on, to
// acc[i0 .. i0 + SPAN - 1]: the row's words from word q on, each block's 64 bits from bit s.
// SPAN and TEXELS (= TEXELS_FOR(16 * SPAN)) come from the kernel; a macro, because a
// kernel's SPAN may be a specialization constant, which sizes no function parameter.
#define ADD_ROW_BLOCKS(acc, i0, texel, q, s)                                                       \
  {                                                                                                \
    uint words_[4 * TEXELS];                                                                       \
    for (int k_ = 0; k_ < TEXELS; ++k_) {                                                          \
      uvec4 x_ = texelFetch(memory, (texel) + k_);                                                 \
      words_[4 * k_] = x_.x;                                                                       \
      words_[4 * k_ + 1] = x_.y;                                                                   \
      words_[4 * k_ + 2] = x_.z;                                                                   \
      words_[4 * k_ + 3] = x_.w;                                                                   \
    }                                                                                              \
    uint v_[2 * SPAN + 1];                                                                         \
    for (int j_ = 0; j_ <= 2 * SPAN; ++j_)                                                         \
      v_[j_] = wordAt(words_[j_], words_[j_ + 1], words_[j_ + 2], words_[j_ + 3], (q));            \
    for (int k_ = 0; k_ < SPAN; ++k_) acc[(i0) + k_] += nibbleBlock(v_[2 * k_], v_[2 * k_ + 1], v_[2 * k_ + 2], (s)); \
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
// the depth gate (match::TemplateDepthGate: anchor cell column and row offsets, least and
// greatest depth in mm), unused.
// A texel buffer: the header's words are read at the workgroup's template, which lavapipe's
// storage-buffer loads would fetch lane by lane.
layout(binding = 1) uniform itextureBuffer header_texels;
int header(int i) { return texelFetch(header_texels, i).x; }
