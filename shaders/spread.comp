#version 450
// LINEMOD spreading: OR of the labels in the T x T window below and right of each pixel,
// as the OR of T row-spread pixels (spread_rows.comp) at and below it. In and out: packed
// label images (common.glsl); kPixelGroup neighbouring rows of one word column per invocation:
// T + kPixelGroup - 1 word loads for 4 kPixelGroup pixels.
#include "common.glsl"
layout(local_size_x = kWorkgroupSize) in;
layout(binding = 0) uniform utextureBuffer rows;  // a fetch is a gather on llvmpipe
layout(std430, binding = 1) writeonly buffer Dst { uint dst[]; };
layout(push_constant) uniform SpreadPushBlock { SpreadPush pc; };
void main() {
  int i = LINEAR_INVOCATION;
  int per_row = wordsPerRow(pc.width);
  int y0, xw;
  if (!columnGroup(i, per_row, pc.height, y0, xw)) return;
  uint acc[kPixelGroup];
  [[unroll]] for (int j = 0; j < kPixelGroup; ++j) acc[j] = 0u;
  for (int t = 0; t < pc.T + kPixelGroup - 1; ++t) {
    uint labels = y0 + t < pc.height ? texelFetch(rows, min(y0 + t, pc.height - 1) * per_row + xw).x : 0u;
    [[unroll]] for (int j = 0; j < kPixelGroup; ++j) acc[j] |= t >= j && t < j + pc.T ? labels : 0u;
  }
  [[unroll]] for (int j = 0; j < kPixelGroup; ++j)
    if (y0 + j < pc.height) dst[(y0 + j) * per_row + xw] = acc[j];
}
