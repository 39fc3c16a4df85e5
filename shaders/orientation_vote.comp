#version 450
// Keeps a pixel's orientation where its magnitude passes the weak threshold and at least 5
// of its 3x3 neighbourhood agree (first bin wins ties). In: sobel_orientation's packed
// bin | 8 if strong. Out: a packed label image (common.glsl) of 1 << bin, or 0.
#include "common.glsl"
layout(local_size_x = kWorkgroupSize) in;
layout(binding = 0) uniform utextureBuffer bins;  // a fetch is a gather on llvmpipe
layout(std430, binding = 1) writeonly buffer Labels { uint labels[]; };
layout(push_constant) uniform SizePushBlock { SizePush pc; };
void main() {
  int i = LINEAR_INVOCATION;
  int y, x0;
  if (!rowWord(i, pc.width, pc.height, y, x0)) return;
  // The 3x3 histograms of bins as 4-bit counts in one word each (at most 9 per bin): no
  // per-lane array indexing, which is a loop over the lanes on llvmpipe. The 4 pixels of a
  // word share the 3 x 3 word loads.
  int per_row = wordsPerRow(pc.width), xw = x0 / 4;
  uint histogram[4];
  [[unroll]] for (int j = 0; j < 4; ++j) histogram[j] = 0u;
  uint centre_word = 0u;
  [[unroll]] for (int dy = -1; dy <= 1; ++dy) {
    int row = clampIndex(y + dy, pc.height) * per_row;
    uvec3 words = wordsAround(bins, row, x0, per_row);
    if (dy == 0) centre_word = words.y;
    [[unroll]] for (int t = 0; t < 6; ++t) {
      uint one = 1u << (4u * (clampedByte(words, x0 + t - 1, x0, pc.width) & 7u));
      [[unroll]] for (int j = 0; j < 4; ++j) histogram[j] += t >= j && t <= j + 2 ? one : 0u;
    }
  }
  uint word = 0u;
  [[unroll]] for (int j = 0; j < 4; ++j) {
    int x = x0 + j;
    uint best = 0u, best_count = histogram[j] & 15u;
    [[unroll]] for (uint b = 1u; b < 8u; ++b) {
      uint count = (histogram[j] >> (4u * b)) & 15u;
      best = count > best_count ? b : best;
      best_count = max(best_count, count);
    }
    // Pixels on the border keep no label, so the clamped neighbours above never count.
    bool inside = x > 0 && y > 0 && x < pc.width - 1 && y < pc.height - 1;
    bool strong = (byteOf(centre_word, j) & 8u) != 0u;
    word |= (inside && strong && best_count >= 5u ? 1u << best : 0u) << (8u * uint(j));
  }
  labels[y * per_row + xw] = word;
}
