#version 450
// Marks the units (refine_grid.glsl) that the refinement windows of this chunk's
// candidates cover: per band of the window one or two blocks, one atomicOr per mark word.
#include "refine_grid.glsl"
layout(local_size_x = 64) in;
layout(std430, binding = 0) readonly buffer Candidates { uint count; uint pad0; uint pad1; uint pad2; uvec4 items[]; };
layout(std430, binding = 1) readonly buffer State { uint unit_count; uint max_units; uint next_candidate; uint first_candidate; };
layout(std430, binding = 2) buffer Marks { uint marks[]; };
layout(push_constant) uniform Push { int template_base; UnitGrid grid; } pc;
void main() {
  uint cand = first_candidate + gl_GlobalInvocationID.y * 32768u * 64u + gl_GlobalInvocationID.x;
  if (cand >= next_candidate) return;
  uvec4 item = items[cand];
  int t = int(item.x) - pc.template_base;
  ivec2 start = windowStart(pc.grid, int(item.y), int(item.z));
  for (int band = bandOf(pc.grid, start.x); band <= bandOf(pc.grid, start.x + 15); ++band) {
    uint first = bandBit(pc.grid, t, band, start.y);
    uint last = bandBit(pc.grid, t, band, start.y + 15);
    uint bits = 1u << (first & 31u);
    if ((last >> 5) == (first >> 5)) {
      bits |= 1u << (last & 31u);
    } else {
      atomicOr(marks[last >> 5], 1u << (last & 31u));
    }
    atomicOr(marks[first >> 5], bits);
  }
}
