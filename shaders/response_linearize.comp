#version 450
// Response maps (quantized cosine: 4 - circular bin distance to the nearest spread
// orientation) written straight into the padded linear memories of one modality. An
// invocation takes CELLS neighbouring cells of one pixel row and grid column (the pixels
// x, x + T, x + 2T, ...) and writes each bin's responses as BLOCKS words, a nibble per cell
// (responses are 0..4; similarity_common.glsl reads them), in one uvec2 store: a store is a
// loop over the lanes on llvmpipe, and one of a uvec2 costs little more than one of a word.
#include "common.glsl"
const int BLOCKS = 2;  // of 8 cells, a word each
const int CELLS = 8 * BLOCKS;
layout(local_size_x = kWorkgroupSize) in;
layout(binding = 0) uniform utextureBuffer spread;  // packed (common.glsl); a fetch is a gather on llvmpipe
layout(std430, binding = 1) writeonly buffer Memory { uvec2 memory[]; };
layout(push_constant) uniform LinearizePushBlock { LinearizePush pc; };
void main() {
  int i = LINEAR_INVOCATION;
  // Aligned groups of CELLS padded cells that hold image cells (the stride, and so the plane
  // size, is a multiple of 32 cells).
  int first_group = pc.pad / CELLS;
  int cells_x = (pc.width + pc.T - 1) / pc.T;
  int groups = (pc.pad + cells_x + CELLS - 1) / CELLS - first_group;
  if (i >= pc.height * pc.T * groups) return;
  int y = i / (pc.T * groups);
  int rest = i - y * pc.T * groups;
  int gx = rest / groups;
  int cell = CELLS * (first_group + rest - gx * groups);  // padded cell column of the first cell
  // All 8 bins' responses of a cell at once, a nibble per bin: a label at bin i gives bin b
  // 4 - circular distance, as a thermometer code (v ones) so that the best over the cell's
  // labels is an OR; the codes of bin i are those of bin 0 rotated by 4 i bits. Counting each
  // nibble's ones turns the codes back into responses. Then each block of 8 cells is
  // transposed, so that block k's word of bin b lands in out_words[BLOCKS * b + k].
  const uint CODES_OF_BIN_0 = 0x7310137Fu;  // bins 0..7: 4, 3, 2, 1, 0, 1, 2, 3
  uint out_words[8 * BLOCKS];
  [[unroll]] for (int k = 0; k < BLOCKS; ++k) {
    uint v[8];
    [[unroll]] for (int j = 0; j < 8; ++j) {
      int x = (cell + 8 * k + j - pc.pad) * pc.T + gx;
      int xc = clamp(x, 0, pc.width - 1);
      uint s = x >= 0 && x < pc.width ? byteOf(texelFetch(spread, y * wordsPerRow(pc.width) + xc / 4).x, xc & 3) : 0u;
      uint codes = 0u;
      [[unroll]] for (int i = 0; i < 8; ++i) {
        uint rotated = i == 0 ? CODES_OF_BIN_0 : (CODES_OF_BIN_0 << (4 * i)) | (CODES_OF_BIN_0 >> (32 - 4 * i));
        codes |= ((s >> uint(i)) & 1u) != 0u ? rotated : 0u;
      }
      v[j] = x >= 0 && x < pc.width ? (codes & 0x11111111u) + ((codes >> 1u) & 0x11111111u) +
                                          ((codes >> 2u) & 0x11111111u) + ((codes >> 3u) & 0x11111111u)
                                    : uint(pc.outside) * 0x11111111u;
    }
    // v[j] holds cell j's bins; the memory wants, per bin, its 8 cells: transpose the 8 x 8
    // nibbles in three rounds of swapping blocks (4 x 4, 2 x 2, then single nibbles).
    [[unroll]] for (int j = 0; j < 4; ++j) {
      uint a = v[j], c = v[j + 4];
      v[j] = (a & 0x0000FFFFu) | (c << 16u);
      v[j + 4] = (a >> 16u) | (c & 0xFFFF0000u);
    }
    [[unroll]] for (int j = 0; j < 8; ++j) {
      if ((j & 2) != 0) continue;
      uint a = v[j], c = v[j + 2];
      v[j] = (a & 0x00FF00FFu) | ((c << 8u) & 0xFF00FF00u);
      v[j + 2] = ((a >> 8u) & 0x00FF00FFu) | (c & 0xFF00FF00u);
    }
    [[unroll]] for (int j = 0; j < 8; j += 2) {
      uint a = v[j], c = v[j + 1];
      v[j] = (a & 0x0F0F0F0Fu) | ((c << 4u) & 0xF0F0F0F0u);
      v[j + 1] = ((a >> 4u) & 0x0F0F0F0Fu) | (c & 0xF0F0F0F0u);
    }
    [[unroll]] for (int b = 0; b < 8; ++b) out_words[BLOCKS * b + k] = v[b];
  }
  uint plane = uint(pc.stride * pc.rows);
  uint word = uint((y / pc.T + pc.pad) * pc.stride + cell) / 8u;
  [[unroll]] for (int b = 0; b < 8; ++b) {
    uint grid = uint(((pc.modality * 8 + b) * pc.T + y % pc.T) * pc.T + gx);
    memory[(grid * (plane / 8u) + word) / uint(BLOCKS)] = uvec2(out_words[BLOCKS * b], out_words[BLOCKS * b + 1]);
  }
}
