#version 450
// Stage 2, finer level: for each coarse candidate of this chunk, the best position in its
// 16 x 16 cell window (first maximum in row-major order), read from the scored units.
#extension GL_EXT_samplerless_texture_functions : require
#include "packed_scores.glsl"
#include "refine_grid.glsl"
layout(local_size_x = 64) in;
layout(binding = 0) uniform utextureBuffer marks;   // r32ui
layout(binding = 1) uniform utextureBuffer bases;   // r32ui
layout(binding = 2) uniform utextureBuffer scores;  // rgba32ui, two texels per unit row
layout(std430, binding = 3) readonly buffer Candidates { uint count; uint pad0; uint pad1; uint pad2; uvec4 items[]; };
layout(std430, binding = 4) readonly buffer State { uint unit_count; uint max_units; uint next_candidate; uint first_candidate; };
layout(std430, binding = 5) writeonly buffer Results { uvec2 results[]; };
layout(push_constant) uniform Push { int template_base; UnitGrid grid; } pc;

uint unitIndex(uint bit) {
  int word = int(bit >> 5);
  uint below = texelFetch(marks, word).x & ((1u << (bit & 31u)) - 1u);
  return texelFetch(bases, word).x + uint(bitCount(below));
}

// Lane masks of the packed scores (lo, hi as packed_scores.glsl reads them) of the block
// positions p with first <= p < end.
void blockMasks(int first, int end, out uvec4 lo_mask, out uvec4 hi_mask) {
  for (int c = 0; c < 4; ++c) {
    int p = 4 * c;
    lo_mask[c] = (p >= first && p < end ? 0xFFFFu : 0u) | (p + 2 >= first && p + 2 < end ? 0xFFFF0000u : 0u);
    hi_mask[c] = (p + 1 >= first && p + 1 < end ? 0xFFFFu : 0u) | (p + 3 >= first && p + 3 < end ? 0xFFFF0000u : 0u);
  }
}

// Per lane, the larger of the two packed 16-bit scores.
uvec4 halvesMax(uvec4 x) { return max(x & 0xFFFFu, x >> 16u); }

// The packed scores of window row `row`: block 0 holds window columns from o on, block 1
// the rest.
void windowRow(ivec2 start, int t, int o, int row, out uvec4 lo0, out uvec4 hi0, out uvec4 lo1, out uvec4 hi1) {
  int band = bandOf(pc.grid, start.x + row);
  int in_band = start.x + row + pc.grid.pad - band * BAND;
  int u0 = int(unitIndex(bandBit(pc.grid, t, band, start.y))) * BAND + in_band;
  int u1 = o == 0 ? u0 : int(unitIndex(bandBit(pc.grid, t, band, start.y + 15))) * BAND + in_band;
  lo0 = texelFetch(scores, 2 * u0);
  hi0 = texelFetch(scores, 2 * u0 + 1);
  lo1 = texelFetch(scores, 2 * u1);
  hi1 = texelFetch(scores, 2 * u1 + 1);
}

void main() {
  uint cand = first_candidate + gl_GlobalInvocationID.y * 32768u * 64u + gl_GlobalInvocationID.x;
  if (cand >= next_candidate) return;
  uvec4 item = items[cand];
  int t = int(item.x) - pc.template_base;
  ivec2 start = windowStart(pc.grid, int(item.y), int(item.z));
  // The window's columns are positions o .. o + 15 of two consecutive blocks (one if o == 0).
  int o = (start.y + pc.grid.pad) & 15;
  uvec4 lo_mask0, hi_mask0, lo_mask1, hi_mask1;
  blockMasks(o, 16, lo_mask0, hi_mask0);
  blockMasks(0, o, lo_mask1, hi_mask1);
  // Each row's best in the window from masked packed maxima; then the first row holding
  // the overall best, and in it the first column: 16 comparisons per row instead of 32
  // position by position.
  uint best = 0u;
  int best_row = 0;
  for (int row = 0; row < 16; ++row) {
    uvec4 lo0, hi0, lo1, hi1;
    windowRow(start, t, o, row, lo0, hi0, lo1, hi1);
    uvec4 m = max(max(halvesMax(lo0 & lo_mask0), halvesMax(hi0 & hi_mask0)),
                  max(halvesMax(lo1 & lo_mask1), halvesMax(hi1 & hi_mask1)));
    uint row_best = max(max(m.x, m.y), max(m.z, m.w));
    best_row = row_best > best ? row : best_row;
    best = max(best, row_best);
  }
  uvec4 lo0, hi0, lo1, hi1;
  windowRow(start, t, o, best_row, lo0, hi0, lo1, hi1);
  int best_column = 0;
  for (int j = 31; j >= 0; --j) {
    uint s = j < 16 ? scoreAt(lo0, hi0, j) : scoreAt(lo1, hi1, j - 16);
    best_column = j >= o && j < o + 16 && s == best ? j - o : best_column;
  }
  results[cand] = uvec2(best, best == 0u ? 0u : uint((best_row << 8) | best_column));
}
