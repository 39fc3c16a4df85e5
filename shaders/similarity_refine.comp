#version 450
// Stage 2, finer level: for each coarse candidate of this chunk's templates, the best
// position in a 16 x 16 cell window around it (first maximum in row-major order).
#include "similarity_common.glsl"
layout(local_size_x = 16) in;
layout(std430, binding = 3) readonly buffer Candidates { uint count; uint pad0; uint pad1; uint pad2; uvec4 items[]; };
layout(std430, binding = 4) writeonly buffer Results { uvec2 results[]; };
layout(push_constant) uniform Push {
  int template_base; int template_count; int T_coarse; int T_fine; int stride; uint capacity;
} pc;
shared uint row_score[16];
shared uint row_col[16];
int floorDiv(int a, int b) { return a >= 0 ? a / b : -((-a + b - 1) / b); }
int windowStart(int coarse_cell) {
  int offset = pc.T_coarse / 2 + (pc.T_coarse % 2 - 1);
  return floorDiv(2 * (coarse_cell * pc.T_coarse + offset) + 1, pc.T_fine) - 8;
}
void main() {
  uint cand = gl_WorkGroupID.y * 32768u + gl_WorkGroupID.x;
  if (cand >= min(count, pc.capacity)) return;  // uniform across the workgroup
  uvec4 item = items[cand];
  int t = int(item.x) - pc.template_base;
  if (t < 0 || t >= pc.template_count) return;  // another chunk's template
  int row = int(gl_LocalInvocationID.x);
  int sr = windowStart(int(item.y)), sc = windowStart(int(item.z));
  int h = t * HEADER_INTS;
  uvec4 lo, hi;
  scoreSixteen(headers[h], headers[h + 1], (sr + row) * pc.stride + sc, lo, hi);
  uint best = 0u, best_col = 0u;
  for (int p = 0; p < 16; ++p) {
    uint s = scoreAt(lo, hi, p);
    if (s > best) { best = s; best_col = uint(p); }
  }
  row_score[row] = best;
  row_col[row] = best_col;
  barrier();
  if (row == 0) {
    uint b = 0u, br = 0u, bc = 0u;
    for (int r = 0; r < 16; ++r)
      if (row_score[r] > b) { b = row_score[r]; br = uint(r); bc = row_col[r]; }
    results[cand] = uvec2(b, (br << 8) | bc);
  }
}
