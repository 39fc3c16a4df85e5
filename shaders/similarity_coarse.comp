#version 450
// Stage 2, coarse level: every template (workgroup row y) at every cell position whose
// template centre lies in the image; positions over the template's raw threshold are
// appended to the candidate list.
#include "similarity_common.glsl"
layout(local_size_x = 64) in;
layout(std430, binding = 3) buffer Candidates { uint count; uint pad0; uint pad1; uint pad2; uvec4 items[]; };
layout(push_constant) uniform Push {
  int template_base;  // global id of this chunk's first template
  int columns;        // positions per row (image cells)
  int rows;           // rows of positions
  int stride;         // bytes per linear-memory row
  int blocks;         // 16-position blocks per row
  uint capacity;      // candidate slots
} pc;
void main() {
  int idx = int(gl_GlobalInvocationID.x);
  if (idx >= pc.rows * pc.blocks) return;
  int t = int(gl_WorkGroupID.y);
  int h = t * HEADER_INTS;
  int row = idx / pc.blocks;
  int block = idx - row * pc.blocks;
  int r = headers[h + 3] + row;
  int c0 = headers[h + 2] + block * 16;
  uvec4 lo, hi;
  scoreSixteen(headers[h], headers[h + 1], r * pc.stride + c0, lo, hi);
  uint threshold = uint(headers[h + 4]);
  for (int p = 0; p < 16 && block * 16 + p < pc.columns; ++p) {
    uint score = scoreAt(lo, hi, p);
    if (score > threshold) {
      uint slot = atomicAdd(count, 1u);
      if (slot < pc.capacity) items[slot] = uvec4(uint(pc.template_base + t), uint(r), uint(c0 + p), score);
    }
  }
}
