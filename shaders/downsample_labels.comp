#version 450
// Nearest-neighbour halving of a label image: pixel (2x, 2y). In and out: packed label
// images (common.glsl); a source word holds 2 of the 4 pixels of an output word.
#include "common.glsl"
layout(local_size_x = kWorkgroupSize) in;
layout(binding = 0) uniform utextureBuffer src;  // a fetch is a gather on llvmpipe
layout(std430, binding = 1) writeonly buffer Dst { uint dst[]; };
layout(push_constant) uniform DownsampleLabelsPushBlock { DownsampleLabelsPush pc; };
void main() {
  int y, x0;
  if (!rowWord(LINEAR_INVOCATION, pc.width, pc.height, y, x0)) return;
  int src_per_row = wordsPerRow(pc.src_width);
  int row = 2 * y * src_per_row, xw = x0 / 2;
  uint a = texelFetch(src, row + xw).x, b = texelFetch(src, row + min(xw + 1, src_per_row - 1)).x;
  // Bytes 0 and 2 of each.
  uint word = (a & 0xFFu) | ((a >> 8u) & 0xFF00u) | ((b & 0xFFu) << 16u) | ((b << 8u) & 0xFF000000u);
  dst[y * wordsPerRow(pc.width) + x0 / 4] = word & insideBytes(x0, pc.width);
}
