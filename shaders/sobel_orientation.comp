#version 450
// Sobel 3x3 per channel of the smoothed image; the strongest channel gives the pixel's
// squared magnitude and orientation bin (0 on the outermost rows and columns). In: packed
// BGRX words (common.glsl).
#include "common.glsl"
layout(local_size_x = 64) in;
layout(std430, binding = 0) readonly buffer Src { uint img[]; };
layout(std430, binding = 1) writeonly buffer Bins { uint8_t bins[]; };
layout(std430, binding = 2) writeonly buffer Mag { int magnitude[]; };
layout(push_constant) uniform Push { int width; int height; } pc;
void main() {
  int i = LINEAR_INVOCATION;
  int y, x0;
  if (!rowGroup(i, pc.width, pc.height, y, x0)) return;
  // GROUP neighbouring pixels of a row (common.glsl) share their 3 x (GROUP + 2) loads.
  int rows[3] = int[](clampIndex(y - 1, pc.height) * pc.width, y * pc.width, clampIndex(y + 1, pc.height) * pc.width);
  int best_gx[GROUP], best_gy[GROUP], best_mag[GROUP];
  [[unroll]] for (int j = 0; j < GROUP; ++j) {
    best_gx[j] = best_gy[j] = 0;
    best_mag[j] = -1;
  }
  uint w[3][GROUP + 2];
  [[unroll]] for (int r = 0; r < 3; ++r)
    [[unroll]] for (int t = 0; t < GROUP + 2; ++t) w[r][t] = img[rows[r] + clampIndex(x0 + t - 1, pc.width)];
  [[unroll]] for (int ch = 0; ch < 3; ++ch) {
    int v[3][GROUP + 2];
    [[unroll]] for (int r = 0; r < 3; ++r)
      [[unroll]] for (int t = 0; t < GROUP + 2; ++t) v[r][t] = int((w[r][t] >> (8u * uint(ch))) & 0xFFu);
    [[unroll]] for (int j = 0; j < GROUP; ++j) {
      // Columns j (left), j + 1 (centre), j + 2 (right) of the loaded window.
      int gx = (v[0][j + 2] + 2 * v[1][j + 2] + v[2][j + 2]) - (v[0][j] + 2 * v[1][j] + v[2][j]);
      int gy = (v[2][j] + 2 * v[2][j + 1] + v[2][j + 2]) - (v[0][j] + 2 * v[0][j + 1] + v[0][j + 2]);
      int mag = gx * gx + gy * gy;
      bool better = mag > best_mag[j];
      best_gx[j] = better ? gx : best_gx[j];
      best_gy[j] = better ? gy : best_gy[j];
      best_mag[j] = better ? mag : best_mag[j];
    }
  }
  [[unroll]] for (int j = 0; j < GROUP; ++j) {
    int x = x0 + j;
    if (x < pc.width) {
      magnitude[y * pc.width + x] = best_mag[j];
      bool border = x == 0 || y == 0 || x == pc.width - 1 || y == pc.height - 1;
      bins[y * pc.width + x] = uint8_t(border ? 0 : gradientOrientationBin(best_gx[j], best_gy[j]));
    }
  }
}
