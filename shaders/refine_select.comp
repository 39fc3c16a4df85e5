#version 450
// Stage 2, finer level: for each coarse candidate of this chunk, the best position in its
// 16 x 16 cell window (first maximum in row-major order), read from the scored units. Only
// the candidates whose best passes the match threshold are listed for the host: on LM-O's
// frame of 8 objects 4.3 M of 7.8 M coarse candidates pass, and reading all of them back
// with their refinements was most of the matcher's host time.
#extension GL_EXT_samplerless_texture_functions : require
#include "packed_scores.glsl"
#include "refine_grid.glsl"
layout(local_size_x = kWorkgroupSize) in;
layout(binding = 0) uniform utextureBuffer blocks;  // r32ui
layout(binding = 1) uniform utextureBuffer bases;   // r32ui
layout(binding = 2) uniform utextureBuffer scores;  // rgba32ui, two texels per unit row
layout(std430, binding = 3) readonly buffer Candidates { uint count; uint pad0; uint pad1; uint pad2; uvec4 items[]; };
layout(std430, binding = 4) readonly buffer State { REFINE_STATE };
// The refined matches: template, coarse row and column (as the candidate), then the score in
// the high 16 bits, the window row and column in bits 8-15 and 0-7.
layout(std430, binding = 5) buffer Refined { uint refined_count; uint rpad0; uint rpad1; uint rpad2; uvec4 refined[]; };
layout(binding = 6) uniform utextureBuffer shifts;  // r32ui, per template band
// The finer level's template headers (similarity_common.glsl): int 4 is the least score
// that passes the threshold there (match::refinedPassScore).
layout(binding = 7) uniform itextureBuffer fine_headers;
layout(push_constant) uniform SelectPushBlock { SelectPush pc; };

uint unitIndex(uint bit) {
  int word = int(bit >> 5);
  uint below = texelFetch(blocks, word).x & ((1u << (bit & 31u)) - 1u);
  return texelFetch(bases, word).x + uint(bitCount(below));
}

// The packed scores of window row `row`: the window's columns are positions o .. o + 15 of
// two consecutive blocks (one if o == 0) of the row's band, whose blocks start at its shift.
void windowRow(ivec2 start, int t, int row, out int o, out uvec4 lo0, out uvec4 hi0, out uvec4 lo1, out uvec4 hi1) {
  int band = bandOf(pc.grid, start.x + row);
  int in_band = start.x + row + pc.grid.pad - band * kUnitBand;
  int column = start.y + pc.grid.pad - int(texelFetch(shifts, t * pc.grid.bands + band).x);
  int k = column >> 4;
  o = column & 15;
  int u0 = int(unitIndex(blockBit(pc.grid, t, band, k))) * kUnitBand + in_band;
  int u1 = o == 0 ? u0 : int(unitIndex(blockBit(pc.grid, t, band, k + 1))) * kUnitBand + in_band;
  lo0 = texelFetch(scores, 2 * u0);
  hi0 = texelFetch(scores, 2 * u0 + 1);
  lo1 = texelFetch(scores, 2 * u1);
  hi1 = texelFetch(scores, 2 * u1 + 1);
}

void main() {
  uint cand = first_candidate + gl_GlobalInvocationID.y * kGridColumns * kWorkgroupSize + gl_GlobalInvocationID.x;
  if (cand >= next_candidate) return;
  uvec4 item = items[cand];
  int t = int(item.x) - pc.template_base;
  ivec2 start = windowStart(pc.grid, int(item.y), int(item.z));
  // Each row's best in the window from masked packed maxima (lo holds positions 4c and
  // 4c + 2, hi 4c + 1 and 4c + 3); then the first row holding the overall best, and in it
  // the first column: 16 comparisons per row instead of 32 position by position.
  const uvec4 even = uvec4(0u, 4u, 8u, 12u);
  uint best = 0u;
  int best_row = 0;
  for (int row = 0; row < 16; ++row) {
    int o;
    uvec4 lo0, hi0, lo1, hi1;
    windowRow(start, t, row, o, lo0, hi0, lo1, hi1);
    uvec4 first = uvec4(uint(o));
    // Block 0 from position o on, block 1 before it.
    uvec4 m0 = max(halvesMax(lo0 & (uvec4(greaterThanEqual(even, first)) * 0xFFFFu |
                                     uvec4(greaterThanEqual(even + 2u, first)) * 0xFFFF0000u)),
                   halvesMax(hi0 & (uvec4(greaterThanEqual(even + 1u, first)) * 0xFFFFu |
                                    uvec4(greaterThanEqual(even + 3u, first)) * 0xFFFF0000u)));
    uvec4 m1 = max(halvesMax(lo1 & (uvec4(lessThan(even, first)) * 0xFFFFu |
                                     uvec4(lessThan(even + 2u, first)) * 0xFFFF0000u)),
                   halvesMax(hi1 & (uvec4(lessThan(even + 1u, first)) * 0xFFFFu |
                                    uvec4(lessThan(even + 3u, first)) * 0xFFFF0000u)));
    uvec4 m = max(m0, m1);
    uint row_best = max(max(m.x, m.y), max(m.z, m.w));
    best_row = row_best > best ? row : best_row;
    best = max(best, row_best);
  }
  int o;
  uvec4 lo0, hi0, lo1, hi1;
  windowRow(start, t, best_row, o, lo0, hi0, lo1, hi1);
  int best_column = 0;
  for (int j = 31; j >= 0; --j) {
    uint s = j < 16 ? scoreAt(lo0, hi0, j) : scoreAt(lo1, hi1, j - 16);
    best_column = j >= o && j < o + 16 && s == best ? j - o : best_column;
  }
  uint pass_score = uint(texelFetch(fine_headers, t * kHeaderInts + 4).x);
  // Appended in a loop that runs only when a lane passes (llvmpipe would run an `if`'s atomic
  // loop over the lanes for every invocation; see similarity_coarse.comp).
  for (uint any = best >= pass_score && best > 0u ? 1u : 0u; any > 0u; --any) {
    uint slot = atomicAdd(refined_count, 1u);
    if (slot < pc.capacity) refined[slot] = uvec4(item.xyz, (best << 16u) | uint((best_row << 8) | best_column));
  }
}
