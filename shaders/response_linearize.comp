#version 450
// Response maps (quantized cosine: 4 - circular bin distance to the nearest spread
// orientation) written straight into the padded linear memories of one modality. An
// invocation takes four neighbouring cells of one pixel row and grid column (the pixels
// x, x + T, x + 2T, x + 3T) and writes each bin's four bytes as one word: a byte store is
// a loop over the lanes on llvmpipe, and four times fewer of them pay.
#include "common.glsl"
layout(local_size_x = 64) in;
layout(std430, binding = 0) readonly buffer Spread { uint8_t spread[]; };
layout(std430, binding = 1) writeonly buffer Memory { uint memory[]; };
layout(push_constant) uniform Push {
  int width; int height; int T; int pad; int stride; int rows; int modality;
} pc;
void main() {
  int i = LINEAR_INVOCATION;
  // Word-aligned groups of four padded cells that hold image cells (the stride and plane
  // size are multiples of 16 bytes).
  int first_quad = pc.pad / 4;
  int cells_x = (pc.width + pc.T - 1) / pc.T;
  int quads = (pc.pad + cells_x + 3) / 4 - first_quad;
  if (i >= pc.height * pc.T * quads) return;
  int y = i / (pc.T * quads);
  int rest = i - y * pc.T * quads;
  int gx = rest / quads;
  int cell = 4 * (first_quad + rest - gx * quads);  // padded cell column of the first byte
  uint s[4];
  for (int j = 0; j < 4; ++j) {
    int x = (cell + j - pc.pad) * pc.T + gx;
    s[j] = x >= 0 && x < pc.width ? uint(spread[y * pc.width + clamp(x, 0, pc.width - 1)]) : 0u;
  }
  uint plane = uint(pc.stride * pc.rows);
  uint word = uint((y / pc.T + pc.pad) * pc.stride + cell) / 4u;
  for (int b = 0; b < 8; ++b) {
    uint packed = 0u;
    for (int j = 0; j < 4; ++j) {
      // Rotate the label set so that bin b is bit 0; bins d away are then bits d and 8 - d.
      uint r = ((s[j] >> b) | (s[j] << (8 - b))) & 0xFFu;
      uint best = (r & 1u) != 0u ? 4u : (r & 0x82u) != 0u ? 3u : (r & 0x44u) != 0u ? 2u : (r & 0x28u) != 0u ? 1u : 0u;
      packed |= best << (8u * uint(j));
    }
    uint grid = uint(((pc.modality * 8 + b) * pc.T + y % pc.T) * pc.T + gx);
    memory[grid * (plane / 4u) + word] = packed;
  }
}
