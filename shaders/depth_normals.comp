#version 450
// LINEMOD's least-squares depth normals: 8 neighbours 5 px away, those differing from the
// centre by difference_threshold or more left out; binned into 8 image-plane directions.
// Out: a packed label image (common.glsl), a word of 4 pixels per invocation.
#include "common.glsl"
layout(local_size_x = kWorkgroupSize) in;
layout(binding = 0) uniform utextureBuffer depth;  // r16ui; a fetch is a gather on llvmpipe
layout(std430, binding = 1) writeonly buffer Labels { uint labels[]; };
layout(push_constant) uniform DepthNormalsPushBlock { DepthNormalsPush pc; };
const int R = 5;
uint normalLabel(int x, int y) {
  int i = y * pc.width + x;
  uint label = 0u;
  int d = int(texelFetch(depth, i).x);
  if (y >= R && y < pc.height - R - 1 && x >= R && x < pc.width - R - 1 && d < pc.distance_threshold) {
    int a0 = 0, a1 = 0, a3 = 0, b0 = 0, b1 = 0;
    for (int j = -R; j <= R; j += R)
      for (int k = -R; k <= R; k += R) {
        if (k == 0 && j == 0) continue;
        int delta = int(texelFetch(depth, i + j * pc.width + k).x) - d;
        if (abs(delta) >= pc.difference_threshold) continue;
        a0 += k * k;
        a1 += k * j;
        a3 += j * j;
        b0 += k * delta;
        b1 += j * delta;
      }
    int det = a0 * a3 - a1 * a1;
    int ddx = a3 * b0 - a1 * b1;
    int ddy = -a1 * b0 + a0 * b1;
    if (!(ddx == 0 && ddy == 0 && det * d == 0)) label = 1u << normalOrientationBin(ddx, ddy);
  }
  return label;
}

void main() {
  int y, x0;
  if (!rowWord(LINEAR_INVOCATION, pc.width, pc.height, y, x0)) return;
  uint word = 0u;
  for (int j = 0; j < 4; ++j)
    if (x0 + j < pc.width) word |= normalLabel(x0 + j, y) << (8u * uint(j));
  labels[y * wordsPerRow(pc.width) + x0 / 4] = word;
}
