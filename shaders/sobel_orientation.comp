#version 450
// Sobel 3x3 per channel of the smoothed image; the strongest channel gives the pixel's
// orientation bin (0 on the outermost rows and columns) and whether its squared magnitude
// passes the weak threshold. In: packed BGRX words. Out: a packed label image (common.glsl)
// of bin | 8 if strong; with write_magnitude, also the squared magnitude per pixel (training
// ranks its feature candidates by it; frames bind a placeholder and skip the stores).
#include "common.glsl"
layout(local_size_x = kWorkgroupSize) in;
layout(binding = 0) uniform utextureBuffer img;  // a fetch is a gather on llvmpipe
layout(std430, binding = 1) writeonly buffer Bins { uint bins[]; };
layout(std430, binding = 2) writeonly buffer Magnitudes { int magnitude[]; };
layout(push_constant) uniform SobelPushBlock { SobelPush pc; };
void main() {
  int i = LINEAR_INVOCATION;
  int y, x0;
  if (!rowWord(i, pc.width, pc.height, y, x0)) return;
  // The 4 pixels of a word share their 3 x 6 loads.
  int rows[3] = int[](clampIndex(y - 1, pc.height) * pc.width, y * pc.width, clampIndex(y + 1, pc.height) * pc.width);
  int best_gx[4], best_gy[4], best_mag[4];
  [[unroll]] for (int j = 0; j < 4; ++j) {
    best_gx[j] = best_gy[j] = 0;
    best_mag[j] = -1;
  }
  uint w[3][6];
  [[unroll]] for (int r = 0; r < 3; ++r)
    [[unroll]] for (int t = 0; t < 6; ++t) w[r][t] = texelFetch(img, rows[r] + clampIndex(x0 + t - 1, pc.width)).x;
  [[unroll]] for (int ch = 0; ch < 3; ++ch) {
    int v[3][6];
    [[unroll]] for (int r = 0; r < 3; ++r)
      [[unroll]] for (int t = 0; t < 6; ++t) v[r][t] = int(byteOf(w[r][t], ch));
    [[unroll]] for (int j = 0; j < 4; ++j) {
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
  uint word = 0u;
  [[unroll]] for (int j = 0; j < 4; ++j) {
    int x = x0 + j;
    bool border = x == 0 || y == 0 || x >= pc.width - 1 || y == pc.height - 1;
    uint bin = border ? 0u : uint(gradientOrientationBin(best_gx[j], best_gy[j]));
    uint strong = float(best_mag[j]) > pc.threshold_sq ? 8u : 0u;
    word |= (bin | strong) << (8u * uint(j));
  }
  bins[y * wordsPerRow(pc.width) + x0 / 4] = word & insideBytes(x0, pc.width);
  if (pc.write_magnitude != 0)
    [[unroll]] for (int j = 0; j < 4; ++j)
      if (x0 + j < pc.width) magnitude[y * pc.width + x0 + j] = best_mag[j];
}
