#version 450
// Stage 2, coarse level: every template (workgroup row y) at every cell position of its
// range (match::coarseRange); positions over the template's raw threshold are
// appended to the candidate list. An invocation scores ROWS rows of 16 positions, so each
// feature's offset is read once for them.
#include "similarity_common.glsl"
layout(local_size_x = 64) in;
layout(std430, binding = 3) buffer Candidates { uint count; uint pad0; uint pad1; uint pad2; uvec4 items[]; };
layout(push_constant) uniform Push {
  int template_base;  // global id of this chunk's first template
  int stride;         // bytes per linear-memory row
  uint capacity;      // candidate slots
} pc;
const int ROWS = 4;  // match kCoarseRows in similarity_gpu.cpp
void main() {
  int idx = int(gl_GlobalInvocationID.x);
  int t = int(gl_WorkGroupID.y);
  int h = t * HEADER_INTS;
  // This template's own range of positions (match::coarseRange): columns, rows.
  int columns = headers[h + 5], rows = headers[h + 6];
  int blocks = (columns + 15) / 16;
  if (idx >= (rows + ROWS - 1) / ROWS * blocks) return;
  int band = idx / blocks;
  int block = idx - band * blocks;
  int r0 = headers[h + 3] + band * ROWS;
  int c0 = headers[h + 2] + block * 16;
  int f = headers[h], end = f + headers[h + 1];
  uint base = uint(r0 * pc.stride + c0), stride = uint(pc.stride);
  uvec4 lo[ROWS], hi[ROWS];
  for (int r = 0; r < ROWS; ++r) lo[r] = hi[r] = uvec4(0u);
  while (f < end) {
    int chunk_end = min(f + 63, end);
    uvec4 acc[ROWS];
    for (int r = 0; r < ROWS; ++r) acc[r] = uvec4(0u);
    for (; f < chunk_end; ++f) {
      uint off = uint(texelFetch(feature_offsets, f).x) + base;
      for (int r = 0; r < ROWS; ++r) acc[r] += sixteenBytes(off + uint(r) * stride);
    }
    for (int r = 0; r < ROWS; ++r) widen(acc[r], lo[r], hi[r]);
  }
  uint threshold = uint(headers[h + 4]);
  for (int r = 0; r < ROWS && band * ROWS + r < rows; ++r)
    for (int p = 0; p < 16 && block * 16 + p < columns; ++p) {
      uint score = scoreAt(lo[r], hi[r], p);
      if (score > threshold) {
        uint slot = atomicAdd(count, 1u);
        if (slot < pc.capacity) items[slot] = uvec4(uint(pc.template_base + t), uint(r0 + r), uint(c0 + p), score);
      }
    }
}
