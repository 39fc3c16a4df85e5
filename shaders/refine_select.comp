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

void main() {
  uint cand = first_candidate + gl_GlobalInvocationID.y * 32768u * 64u + gl_GlobalInvocationID.x;
  if (cand >= next_candidate) return;
  uvec4 item = items[cand];
  int t = int(item.x) - pc.template_base;
  ivec2 start = windowStart(pc.grid, int(item.y), int(item.z));
  // The window's columns are positions o .. o + 15 of two consecutive blocks (one if o == 0).
  int o = (start.y + pc.grid.pad) & 15;
  uint best = 0u, best_pos = 0u;
  for (int row = 0; row < 16; ++row) {
    int band = bandOf(pc.grid, start.x + row);
    int in_band = start.x + row + pc.grid.pad - band * BAND;
    int u0 = int(unitIndex(bandBit(pc.grid, t, band, start.y))) * BAND + in_band;
    int u1 = o == 0 ? u0 : int(unitIndex(bandBit(pc.grid, t, band, start.y + 15))) * BAND + in_band;
    uvec4 lo0 = texelFetch(scores, 2 * u0), hi0 = texelFetch(scores, 2 * u0 + 1);
    uvec4 lo1 = texelFetch(scores, 2 * u1), hi1 = texelFetch(scores, 2 * u1 + 1);
    for (int j = 0; j < 32; ++j) {
      uint s = j < 16 ? scoreAt(lo0, hi0, j) : scoreAt(lo1, hi1, j - 16);
      if (j >= o && j < o + 16 && s > best) {
        best = s;
        best_pos = uint((row << 8) | (j - o));
      }
    }
  }
  results[cand] = uvec2(best, best_pos);
}
