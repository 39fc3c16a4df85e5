#version 450
// Marks the padded columns (refine_grid.glsl) that the refinement windows of this chunk's
// candidates cover, per template and band of the window: 16 bits, one or two atomicOr,
// and the band's bit in the occupancy mask that refine_units.comp reads first.
#include "refine_grid.glsl"
layout(local_size_x = kWorkgroupSize) in;
layout(std430, binding = 0) readonly buffer Candidates { uint count; uint pad0; uint pad1; uint pad2; uvec4 items[]; };
layout(std430, binding = 1) readonly buffer State { REFINE_STATE };
layout(std430, binding = 2) buffer ColumnMarks { uint columns[]; };
layout(std430, binding = 3) buffer Occupied { uint occupied[]; };  // a bit per template band
layout(push_constant) uniform ChunkPushBlock { ChunkPush pc; };
void main() {
  uint cand = first_candidate + gl_GlobalInvocationID.y * kGridColumns * kWorkgroupSize + gl_GlobalInvocationID.x;
  if (cand >= next_candidate) return;
  uvec4 item = items[cand];
  int t = int(item.x) - pc.template_base;
  ivec2 start = windowStart(pc.grid, int(item.y), int(item.z));
  for (int band = bandOf(pc.grid, start.x); band <= bandOf(pc.grid, start.x + 15); ++band) {
    uint tb = uint(t * pc.grid.bands + band);
    atomicOr(occupied[tb >> 5], 1u << (tb & 31u));
    uint bit = tb * uint(pc.grid.column_words * 32) + uint(start.y + pc.grid.pad);
    uint s = bit & 31u;
    atomicOr(columns[bit >> 5], 0xFFFFu << s);
    if (s > 16u) atomicOr(columns[(bit >> 5) + 1u], 0xFFFFu >> (32u - s));
  }
}
