#version 450
// Numbers the units marked by refine_mark.comp. Each non-zero mark word gets a range of
// unit slots, where similarity_refine.comp writes each unit's scores (the order across
// words does not matter). Its runs of consecutive marked units (neighbouring 16-cell
// blocks of one band) are cut into pieces of at most MAX_SPAN units and listed by length:
// a piece of L units costs L + 1 texel fetches per row and feature, where units one by one
// would cost 2 L.
#include "refine_grid.glsl"
layout(local_size_x = 64) in;
layout(std430, binding = 0) readonly buffer Marks { uint marks[]; };
layout(std430, binding = 1) writeonly buffer Bases { uint bases[]; };
layout(std430, binding = 2) writeonly buffer Runs { uvec2 runs[]; };
layout(std430, binding = 3) buffer State { REFINE_STATE };
layout(push_constant) uniform Push { uint words; uint capacity; } pc;
void main() {
  uint i = gl_GlobalInvocationID.y * 32768u * 64u + gl_GlobalInvocationID.x;
  if (i >= pc.words) return;
  uint m = marks[i];
  if (m == 0u) return;
  uint slot = atomicAdd(unit_count, uint(bitCount(m)));
  bases[i] = slot;
  while (m != 0u) {
    int b = findLSB(m);
    uint rest = m >> uint(b);
    int len = rest == 0xFFFFFFFFu ? 32 - b : findLSB(~rest);
    m &= len == 32 ? 0u : ~(((1u << uint(len)) - 1u) << uint(b));
    for (int p = 0; p < len; p += MAX_SPAN) {
      int span = min(MAX_SPAN, len - p);
      uint k = atomicAdd(run_count[span - 1], 1u);
      if (k < runCapacity(pc.capacity, span))
        runs[runRegion(pc.capacity, span) + k] = uvec2(i * 32u + uint(b + p), slot + uint(p));
    }
    slot += uint(len);
  }
}
