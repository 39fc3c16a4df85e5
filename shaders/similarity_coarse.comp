#version 450
// Stage 2, coarse level: every template (workgroup row y) at every cell position of its
// range (match::coarseRange); positions over the template's raw threshold are
// appended to the candidate list. An invocation scores ROWS rows of SPAN blocks of 16
// positions: per row and feature TEXELS texels of 32 nibbles, where a lane per block would
// fetch two each (the fetches are what the pass costs on llvmpipe).
#include "similarity_common.glsl"
layout(local_size_x = 16) in;  // kCoarseGroup in similarity_gpu.cpp
layout(std430, binding = 3) buffer Candidates { uint count; uint pad0; uint pad1; uint pad2; uvec4 items[]; };
layout(push_constant) uniform Push {
  int template_base;  // global id of this chunk's first template
  int stride;         // cells per linear-memory row (a multiple of 32)
  uint capacity;      // candidate slots
} pc;
const int ROWS = 2;  // match kCoarseRows in similarity_gpu.cpp
const int SPAN = 3;  // match kCoarseSpan in similarity_gpu.cpp
const int TEXELS = TEXELS_FOR(16 * SPAN);
void main() {
  int idx = int(gl_GlobalInvocationID.x);
  int t = int(gl_WorkGroupID.y);
  int h = t * HEADER_INTS;
  // This template's own range of positions (match::coarseRange): columns, rows.
  int columns = headers[h + 5], rows = headers[h + 6];
  int spans = (columns + 16 * SPAN - 1) / (16 * SPAN);
  if (idx >= (rows + ROWS - 1) / ROWS * spans) return;
  int band = idx / spans;
  int span = idx - band * spans;
  int r0 = headers[h + 3] + band * ROWS;
  int c0 = headers[h + 2] + span * 16 * SPAN;
  int f = headers[h], end = f + headers[h + 1];
  uint base = uint(r0 * pc.stride + c0);
  int row_texels = pc.stride / 32;
  uvec4 lo[ROWS * SPAN], hi[ROWS * SPAN];
  for (int i = 0; i < ROWS * SPAN; ++i) lo[i] = hi[i] = uvec4(0u);
  while (f < end) {
    int chunk_end = min(f + FEATURES_PER_8BIT, end);
    uvec4 acc[ROWS * SPAN];
    for (int i = 0; i < ROWS * SPAN; ++i) acc[i] = uvec4(0u);
    for (; f < chunk_end; ++f) {
      // Nibble offset of the first position for this feature.
      int first;
      uint q, s;
      nibbleAddress(uint(texelFetch(feature_offsets, f).x) + base, first, q, s);
      for (int r = 0; r < ROWS; ++r) ADD_ROW_BLOCKS(acc, r * SPAN, first + r * row_texels, q, s)
    }
    for (int i = 0; i < ROWS * SPAN; ++i) widenSplit(acc[i], lo[i], hi[i]);
  }
  uint threshold = uint(headers[h + 4]);
  // Few positions pass. llvmpipe runs both sides of every `if` under a lane mask, so the
  // appending below (an atomic is a loop over the lanes) would cost every invocation;
  // a loop whose count is 0 unless some position passes is skipped when no lane enters it.
  uint best = 0u;
  for (int i = 0; i < ROWS * SPAN; ++i) best = max(best, maxOfSixteen(lo[i], hi[i]));
  for (uint any = best > threshold ? 1u : 0u; any > 0u; --any)
  for (int r = 0; r < ROWS; ++r)
    for (int k = 0; k < SPAN; ++k)
      for (int p = 0; p < 16; ++p) {
        uint score = scoreAt(lo[r * SPAN + k], hi[r * SPAN + k], p);
        int column = span * 16 * SPAN + k * 16 + p;
        if (score > threshold && band * ROWS + r < rows && column < columns) {
          uint slot = atomicAdd(count, 1u);
          if (slot < pc.capacity) items[slot] = uvec4(uint(pc.template_base + t), uint(r0 + r), uint(headers[h + 2] + column), score);
        }
      }
}
