#version 450
// Stage 2, finer level: for each coarse candidate of this chunk's templates, the best
// position in a 16 x 16 cell window around it (first maximum in row-major order). One
// invocation per candidate scores the whole window: no barrier (which makes llvmpipe run a
// workgroup as coroutines), and each feature's offset is read once for the 16 rows.
#include "similarity_common.glsl"
layout(local_size_x = 32) in;
layout(std430, binding = 3) readonly buffer Candidates { uint count; uint pad0; uint pad1; uint pad2; uvec4 items[]; };
layout(std430, binding = 4) writeonly buffer Results { uvec2 results[]; };
layout(push_constant) uniform Push {
  int template_base; int template_count; int T_coarse; int T_fine; int stride; uint capacity;
} pc;
int floorDiv(int a, int b) { return a >= 0 ? a / b : -((-a + b - 1) / b); }
int windowStart(int coarse_cell) {
  int offset = pc.T_coarse / 2 + (pc.T_coarse % 2 - 1);
  return floorDiv(2 * (coarse_cell * pc.T_coarse + offset) + 1, pc.T_fine) - 8;
}
void main() {
  uint cand = gl_GlobalInvocationID.y * 32768u * 32u + gl_GlobalInvocationID.x;
  if (cand >= min(count, pc.capacity)) return;  // the last workgroup's spare invocations
  uvec4 item = items[cand];
  int t = int(item.x) - pc.template_base;
  if (t < 0 || t >= pc.template_count) return;  // another chunk's template
  int sr = windowStart(int(item.y)), sc = windowStart(int(item.z));
  int h = t * HEADER_INTS;
  int f = headers[h], end = f + headers[h + 1];
  int base = sr * pc.stride + sc;
  uvec4 lo[16], hi[16];
  for (int r = 0; r < 16; ++r) { lo[r] = uvec4(0u); hi[r] = uvec4(0u); }
  while (f < end) {
    int chunk_end = min(f + 63, end);
    uvec4 acc[16];
    for (int r = 0; r < 16; ++r) acc[r] = uvec4(0u);
    for (; f < chunk_end; ++f) {
      uint off = uint(feature_offsets[f] + base);
      for (int r = 0; r < 16; ++r) {
        acc[r] += sixteenBytes(off);
        off += uint(pc.stride);
      }
    }
    for (int r = 0; r < 16; ++r) widen(acc[r], lo[r], hi[r]);
  }
  uint best = 0u, best_pos = 0u;
  for (int row = 0; row < 16; ++row) {
    for (int p = 0; p < 16; ++p) {
      uint s = scoreAt(lo[row], hi[row], p);
      if (s > best) { best = s; best_pos = uint((row << 8) | p); }
    }
  }
  results[cand] = uvec2(best, best_pos);
}
