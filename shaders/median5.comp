#version 450
// 5x5 median of label values, replicated border (OpenCV's medianBlur(5) on 8 bits).
#include "common.glsl"
layout(local_size_x = 64) in;
layout(std430, binding = 0) readonly buffer Src { uint8_t src[]; };
layout(std430, binding = 1) writeonly buffer Dst { uint8_t dst[]; };
layout(push_constant) uniform Push { int width; int height; } pc;
// The 4 low bits of v, one per byte.
uint bitsToBytes(uint v) { return (v & 1u) | ((v & 2u) << 7u) | ((v & 4u) << 14u) | ((v & 8u) << 21u); }

void main() {
  int i = LINEAR_INVOCATION;
  if (i >= pc.width * pc.height) return;
  int y = i / pc.width, x = i - y * pc.width;
  // Labels take 9 values (0 and 1 << b): the median is the value where the running count
  // of a 9-bin histogram first exceeds 12. The histogram of bins 1..8 is a byte per label
  // bit in two words (each count at most 25), so no per-lane array indexing (an indirect
  // array access is a loop over the lanes on llvmpipe).
  uint low = 0u, high = 0u;
  for (int dy = -2; dy <= 2; ++dy)
    for (int dx = -2; dx <= 2; ++dx) {
      uint v = uint(src[clampIndex(y + dy, pc.height) * pc.width + clampIndex(x + dx, pc.width)]);
      low += bitsToBytes(v & 15u);
      high += bitsToBytes(v >> 4);
    }
  uint counts = low + high;
  int seen = 25 - int((counts & 0xFFu) + ((counts >> 8) & 0xFFu) + ((counts >> 16) & 0xFFu) + (counts >> 24));
  uint median = 0u;
  bool found = seen > 12;
  for (int b = 0; b < 8; ++b) {
    seen += int(((b < 4 ? low : high) >> (8u * uint(b & 3))) & 0xFFu);
    median = !found && seen > 12 ? 1u << uint(b) : median;
    found = found || seen > 12;
  }
  dst[i] = uint8_t(median);
}
