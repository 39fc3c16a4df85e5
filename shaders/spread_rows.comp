#version 450
// First half of LINEMOD spreading: OR of the labels in the T pixels at and right of each
// pixel (none past the width). spread.comp then ORs T of these downwards: T + T loads
// instead of T * T. In and out: packed label images (common.glsl); a word of 4 pixels per
// invocation, whose windows span T + 3 pixels: T / 4 + 2 word loads at most.
#include "common.glsl"
layout(local_size_x = kWorkgroupSize) in;
layout(binding = 0) uniform utextureBuffer src;  // a fetch is a gather on llvmpipe
layout(std430, binding = 1) writeonly buffer Dst { uint dst[]; };
layout(push_constant) uniform SpreadPushBlock { SpreadPush pc; };
void main() {
  int y, x0;
  if (!rowWord(LINEAR_INVOCATION, pc.width, pc.height, y, x0)) return;
  int per_row = wordsPerRow(pc.width), xw = x0 / 4, row = y * per_row;
  // The word of pixels x0 + s .. x0 + s + 3 is word q = s / 4 after x0 shifted down by
  // s % 4 bytes, the next word's low bytes filling in; the bytes past the width are 0, as are
  // the words past the row.
  uint acc = 0u, current = texelFetch(src, row + xw).x;
  for (int q = 0; 4 * q < pc.T; ++q) {
    uint next = xw + q + 1 < per_row ? texelFetch(src, row + xw + q + 1).x : 0u;
    [[unroll]] for (int r = 0; r < 4; ++r)
      if (4 * q + r < pc.T) acc |= r == 0 ? current : (current >> (8u * uint(r))) | (next << (32u - 8u * uint(r)));
    current = next;
  }
  dst[row + xw] = acc;
}
