#version 450
// Sobel 3x3 per channel of the smoothed image; the strongest channel gives the pixel's
// squared magnitude and orientation bin (0 on the outermost rows and columns).
#include "common.glsl"
layout(local_size_x = 64) in;
layout(std430, binding = 0) readonly buffer Src { uint8_t img[]; };
layout(std430, binding = 1) writeonly buffer Bins { uint8_t bins[]; };
layout(std430, binding = 2) writeonly buffer Mag { int magnitude[]; };
layout(push_constant) uniform Push { int width; int height; } pc;
int px(int y, int x, int ch) { return int(img[(y * pc.width + x) * 3 + ch]); }
void main() {
  int i = LINEAR_INVOCATION;
  if (i >= pc.width * pc.height) return;
  int y = i / pc.width, x = i - y * pc.width;
  int u = clampIndex(y - 1, pc.height), d = clampIndex(y + 1, pc.height);
  int l = clampIndex(x - 1, pc.width), r = clampIndex(x + 1, pc.width);
  int best_gx = 0, best_gy = 0, best_mag = -1;
  for (int ch = 0; ch < 3; ++ch) {
    int gx = (px(u, r, ch) + 2 * px(y, r, ch) + px(d, r, ch)) - (px(u, l, ch) + 2 * px(y, l, ch) + px(d, l, ch));
    int gy = (px(d, l, ch) + 2 * px(d, x, ch) + px(d, r, ch)) - (px(u, l, ch) + 2 * px(u, x, ch) + px(u, r, ch));
    int mag = gx * gx + gy * gy;
    if (mag > best_mag) { best_mag = mag; best_gx = gx; best_gy = gy; }
  }
  magnitude[i] = best_mag;
  bool border = x == 0 || y == 0 || x == pc.width - 1 || y == pc.height - 1;
  bins[i] = uint8_t(border ? 0 : gradientOrientationBin(best_gx, best_gy));
}
