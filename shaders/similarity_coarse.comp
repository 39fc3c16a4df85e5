#version 450
// Stage 2, coarse level: every template (workgroup row y) at every cell position of its
// range (match::coarseRange); positions over the template's raw threshold are
// appended to the candidate list. An invocation scores kCoarseRows rows of SPAN blocks of 16
// positions: per row and feature TEXELS texels of 32 nibbles, where a lane per block would
// fetch two each (the fetches are what the pass costs on llvmpipe).
//
// Depth-guided pruning (match/depth_gate.hpp): with anchor cells bound, a template's range is
// clipped to its depth band's box (the anchor cells that meet the band), an invocation whose
// strip of positions has no anchor cell within the template's depth gate reads nothing, and
// a passing position is appended only when its own anchor cell is within the gate.
#include "similarity_common.glsl"
layout(local_size_x = kCoarseWorkgroupSize) in;
layout(std430, binding = 3) buffer Candidates { uint count; uint pad0; uint pad1; uint pad2; uvec4 items[]; };
// Anchor cells' depth intervals (least | greatest << 16, mm): plane 0 per cell, plane 1 + k
// rows r and r + 1 over columns c .. c + 2^k - 1 (match::AnchorDepthCells).
layout(binding = 4) uniform utextureBuffer depth_cells;
layout(push_constant) uniform CoarsePushBlock { CoarsePush pc; };

uint depthCell(int plane, int r, int c) { return texelFetch(depth_cells, (plane * pc.cells_y + r) * pc.cells_x + c).x; }
bool meets(uint interval, int z_lo, int z_hi) { return int(interval & 0xFFFFu) <= z_hi && int(interval >> 16u) >= z_lo; }

// match::positionPasses (anchor cell (ra, ca), clamped to the grid)
bool positionPasses(int ra, int ca, int z_lo, int z_hi) {
  if (pc.cells_x == 0) return true;
  return meets(depthCell(0, clamp(ra, 0, pc.cells_y - 1), clamp(ca, 0, pc.cells_x - 1)), z_lo, z_hi);
}

// match::stripMayPass (anchor cells from (ra, ca), clamped to the grid)
bool stripMayPass(int ra, int ca, int columns, int z_lo, int z_hi) {
  if (pc.cells_x == 0) return true;
  int r0 = clamp(ra, 0, pc.cells_y - 1);
  int c0 = clamp(ca, 0, pc.cells_x - 1), c1 = clamp(ca + columns - 1, 0, pc.cells_x - 1);
  int k = findMSB(c1 - c0 + 1);
  uint a = depthCell(1 + k, r0, c0), b = depthCell(1 + k, r0, c1 + 1 - (1 << k));
  uint interval = min(a & 0xFFFFu, b & 0xFFFFu) | (max(a >> 16u, b >> 16u) << 16u);
  return meets(interval, z_lo, z_hi);
}
const int SPAN = kCoarseSpan;  // ADD_ROW_BLOCKS reads SPAN
const int TEXELS = TEXELS_FOR(16 * SPAN);
void main() {
  int idx = int(gl_GlobalInvocationID.x);
  int t = int(gl_WorkGroupID.y);
  int h = t * kHeaderInts;
  // This template's own range of positions (match::coarseRange): first column and row,
  // columns, rows; with pruning, clipped to its depth band's box (match::clipToBox).
  int c_lo = header(h + 2), r_lo = header(h + 3), columns = header(h + 5), rows = header(h + 6);
  int anchor_dc = header(h + 7), anchor_dr = header(h + 8), z_lo = header(h + 9), z_hi = header(h + 10);
  if (pc.cells_x != 0) {
    int b = pc.boxes_at + 4 * header(h + 11);
    ivec4 box = ivec4(texelFetch(depth_cells, b).x, texelFetch(depth_cells, b + 1).x, texelFetch(depth_cells, b + 2).x,
                      texelFetch(depth_cells, b + 3).x);
    int r_hi = min(r_lo + rows, box.y - anchor_dr), c_hi = min(c_lo + columns, box.w - anchor_dc);
    r_lo = max(r_lo, box.x - anchor_dr);
    c_lo = max(c_lo, box.z - anchor_dc);
    rows = max(0, r_hi - r_lo);
    columns = max(0, c_hi - c_lo);
    if (rows == 0 || columns == 0) return;
  }
  int spans = (columns + 16 * SPAN - 1) / (16 * SPAN);
  if (idx >= (rows + kCoarseRows - 1) / kCoarseRows * spans) return;
  int band = idx / spans;
  int span = idx - band * spans;
  int r0 = r_lo + band * kCoarseRows;
  int c0 = c_lo + span * 16 * SPAN;
  int f = header(h), end = f + header(h + 1);
  // A strip that cannot pass reads no memory: no features to add (llvmpipe skips the loop
  // when none of a vector's lanes enters it).
  if (!stripMayPass(r0 + anchor_dr, c0 + anchor_dc, min(16 * SPAN, columns - span * 16 * SPAN), z_lo, z_hi)) end = f;
  uint base = uint(r0 * pc.stride + c0);
  int row_texels = pc.stride / 32;
  uvec4 lo[kCoarseRows * SPAN], hi[kCoarseRows * SPAN];
  for (int i = 0; i < kCoarseRows * SPAN; ++i) lo[i] = hi[i] = uvec4(0u);
  while (f < end) {
    int chunk_end = min(f + kFeaturesPer8Bit, end);
    uvec4 acc[kCoarseRows * SPAN];
    for (int i = 0; i < kCoarseRows * SPAN; ++i) acc[i] = uvec4(0u);
    for (; f < chunk_end; ++f) {
      // Nibble offset of the first position for this feature.
      int first;
      uint q, s;
      nibbleAddress(uint(texelFetch(feature_offsets, f).x) + base, first, q, s);
      for (int r = 0; r < kCoarseRows; ++r) ADD_ROW_BLOCKS(acc, r * SPAN, first + r * row_texels, q, s)
    }
    for (int i = 0; i < kCoarseRows * SPAN; ++i) widenSplit(acc[i], lo[i], hi[i]);
  }
  uint threshold = uint(header(h + 4));
  // Few positions pass. llvmpipe runs both sides of every `if` under a lane mask, so the
  // appending below (an atomic is a loop over the lanes) would cost every invocation;
  // a loop whose count is 0 unless some position passes is skipped when no lane enters it.
  uint best = 0u;
  for (int i = 0; i < kCoarseRows * SPAN; ++i) best = max(best, maxOfSixteen(lo[i], hi[i]));
  for (uint any = best > threshold ? 1u : 0u; any > 0u; --any)
  for (int r = 0; r < kCoarseRows; ++r)
    for (int k = 0; k < SPAN; ++k)
      for (int p = 0; p < 16; ++p) {
        uint score = scoreAt(lo[r * SPAN + k], hi[r * SPAN + k], p);
        int column = span * 16 * SPAN + k * 16 + p;
        if (score > threshold && band * kCoarseRows + r < rows && column < columns &&
            positionPasses(r0 + r + anchor_dr, c_lo + column + anchor_dc, z_lo, z_hi)) {
          uint slot = atomicAdd(count, 1u);
          if (slot < pc.capacity) items[slot] = uvec4(uint(pc.template_base + t), uint(r0 + r), uint(c_lo + column), score);
        }
      }
}
