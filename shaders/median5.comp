#version 450
// 5x5 median of label values, replicated border (OpenCV's medianBlur(5) on 8 bits). In and
// out: packed label images (common.glsl).
#include "common.glsl"
layout(local_size_x = kWorkgroupSize) in;
layout(binding = 0) uniform utextureBuffer src;  // a fetch is a gather on llvmpipe
layout(std430, binding = 1) writeonly buffer Dst { uint dst[]; };
layout(push_constant) uniform SizePushBlock { SizePush pc; };
// The 4 low bits of v, one per byte.
uint bitsToBytes(uint v) { return (v & 1u) | ((v & 2u) << 7u) | ((v & 4u) << 14u) | ((v & 8u) << 21u); }

void main() {
  int i = LINEAR_INVOCATION;
  int y, x0;
  if (!rowWord(i, pc.width, pc.height, y, x0)) return;
  // Labels take 9 values (0 and 1 << b): the median is the value where the running count
  // of a 9-bin histogram first exceeds 12. The histogram of bins 1..8 is a byte per label
  // bit in two words (each count at most 25), so no per-lane array indexing. The 4 pixels
  // of a word share the 5 x 3 word loads.
  int per_row = wordsPerRow(pc.width), xw = x0 / 4;
  uint low[4], high[4];
  [[unroll]] for (int j = 0; j < 4; ++j) low[j] = high[j] = 0u;
  [[unroll]] for (int dy = -2; dy <= 2; ++dy) {
    int row = clampIndex(y + dy, pc.height) * per_row;
    uvec3 words = wordsAround(src, row, x0, per_row);
    [[unroll]] for (int t = 0; t < 8; ++t) {
      uint v = clampedByte(words, x0 + t - 2, x0, pc.width);
      uint l = bitsToBytes(v & 15u), h = bitsToBytes(v >> 4);
      [[unroll]] for (int j = 0; j < 4; ++j)
        if (t >= j && t <= j + 4) {
          low[j] += l;
          high[j] += h;
        }
    }
  }
  uint word = 0u;
  [[unroll]] for (int j = 0; j < 4; ++j) {
    uint counts = low[j] + high[j];
    int seen = 25 - int((counts & 0xFFu) + ((counts >> 8) & 0xFFu) + ((counts >> 16) & 0xFFu) + (counts >> 24));
    uint median = 0u;
    bool found = seen > 12;
    [[unroll]] for (int b = 0; b < 8; ++b) {
      seen += int(((b < 4 ? low[j] : high[j]) >> (8u * uint(b & 3))) & 0xFFu);
      median = !found && seen > 12 ? 1u << uint(b) : median;
      found = found || seen > 12;
    }
    word |= median << (8u * uint(j));
  }
  dst[y * per_row + xw] = word & insideBytes(x0, pc.width);
}
