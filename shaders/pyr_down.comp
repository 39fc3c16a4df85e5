#version 450
// Next pyramid level of the colour image: 5x5 binomial, every second pixel, reflected border.
#include "common.glsl"
layout(local_size_x = 64) in;
layout(std430, binding = 0) readonly buffer Src { uint8_t src[]; };
layout(std430, binding = 1) writeonly buffer Dst { uint8_t dst[]; };
layout(push_constant) uniform Push { int src_width; int src_height; int width; int height; } pc;
const int k[5] = int[](1, 4, 6, 4, 1);
void main() {
  int i = LINEAR_INVOCATION;
  if (i >= pc.width * pc.height) return;
  int y = i / pc.width, x = i - y * pc.width;
  int cols[5];
  for (int t = 0; t < 5; ++t) cols[t] = reflect101Index(2 * x + t - 2, pc.src_width);
  for (int ch = 0; ch < 3; ++ch) {
    int acc = 0;
    for (int j = 0; j < 5; ++j) {
      int row = reflect101Index(2 * y + j - 2, pc.src_height) * pc.src_width;
      int racc = 0;
      for (int t = 0; t < 5; ++t) racc += k[t] * int(src[(row + cols[t]) * 3 + ch]);
      acc += k[j] * racc;
    }
    dst[i * 3 + ch] = uint8_t((acc + 128) >> 8);
  }
}
