#version 450
// Response maps (quantized cosine: 4 - circular bin distance to the nearest spread
// orientation) written straight into the padded linear memories of one modality. An
// invocation takes CELLS neighbouring cells of one pixel row and grid column (the pixels
// x, x + T, x + 2T, ...) and writes each bin's responses as one word, a nibble per cell
// (responses are 0..4; similarity_common.glsl reads them): a byte store is a loop over the
// lanes on llvmpipe, and far fewer of them pay.
#include "common.glsl"
const int CELLS = 8;
const uint BITS = 4u;
layout(local_size_x = 64) in;
layout(std430, binding = 0) readonly buffer Spread { uint8_t spread[]; };
layout(std430, binding = 1) writeonly buffer Memory { uint memory[]; };
layout(push_constant) uniform Push {
  int width; int height; int T; int pad; int stride; int rows; int modality;
} pc;
void main() {
  int i = LINEAR_INVOCATION;
  // Word-aligned groups of CELLS padded cells that hold image cells (the stride, and so the
  // plane size, is a multiple of 32 cells).
  int first_group = pc.pad / CELLS;
  int cells_x = (pc.width + pc.T - 1) / pc.T;
  int groups = (pc.pad + cells_x + CELLS - 1) / CELLS - first_group;
  if (i >= pc.height * pc.T * groups) return;
  int y = i / (pc.T * groups);
  int rest = i - y * pc.T * groups;
  int gx = rest / groups;
  int cell = CELLS * (first_group + rest - gx * groups);  // padded cell column of the first cell
  uint s[CELLS];
  [[unroll]] for (int j = 0; j < CELLS; ++j) {
    int x = (cell + j - pc.pad) * pc.T + gx;
    s[j] = x >= 0 && x < pc.width ? uint(spread[y * pc.width + clamp(x, 0, pc.width - 1)]) : 0u;
  }
  uint plane = uint(pc.stride * pc.rows);
  uint word = uint((y / pc.T + pc.pad) * pc.stride + cell) / uint(CELLS);
  for (int b = 0; b < 8; ++b) {
    uint packed = 0u;
    [[unroll]] for (int j = 0; j < CELLS; ++j) {
      // Rotate the label set so that bin b is bit 0; bins d away are then bits d and 8 - d.
      uint r = ((s[j] >> b) | (s[j] << (8 - b))) & 0xFFu;
      uint best = (r & 1u) != 0u ? 4u : (r & 0x82u) != 0u ? 3u : (r & 0x44u) != 0u ? 2u : (r & 0x28u) != 0u ? 1u : 0u;
      packed |= best << (BITS * uint(j));
    }
    uint grid = uint(((pc.modality * 8 + b) * pc.T + y % pc.T) * pc.T + gx);
    memory[grid * (plane / uint(CELLS)) + word] = packed;
  }
}
