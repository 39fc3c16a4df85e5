#version 450
// Keeps a pixel's orientation where its magnitude passes the weak threshold and at least 5
// of its 3x3 neighbourhood agree (first bin wins ties). Output: 1 << bin, or 0.
#include "common.glsl"
layout(local_size_x = 64) in;
layout(std430, binding = 0) readonly buffer Bins { uint8_t bins[]; };
layout(std430, binding = 1) readonly buffer Mag { int magnitude[]; };
layout(std430, binding = 2) writeonly buffer Labels { uint8_t labels[]; };
layout(push_constant) uniform Push { int width; int height; float threshold_sq; } pc;
void main() {
  int i = LINEAR_INVOCATION;
  int y, x0;
  if (!rowGroup(i, pc.width, pc.height, y, x0)) return;
  // The 3x3 histograms of bins as 4-bit counts in one word each (at most 9 per bin): no
  // per-lane array indexing, which is a loop over the lanes on llvmpipe. GROUP neighbouring
  // pixels of a row (common.glsl) share the 3 x (GROUP + 2) loads.
  uint histogram[GROUP];
  [[unroll]] for (int j = 0; j < GROUP; ++j) histogram[j] = 0u;
  [[unroll]] for (int dy = -1; dy <= 1; ++dy) {
    int row = clampIndex(y + dy, pc.height) * pc.width;
    [[unroll]] for (int t = 0; t < GROUP + 2; ++t) {
      uint one = 1u << (4u * uint(bins[row + clampIndex(x0 + t - 1, pc.width)]));
      [[unroll]] for (int j = 0; j < GROUP; ++j) histogram[j] += t >= j && t <= j + 2 ? one : 0u;
    }
  }
  [[unroll]] for (int j = 0; j < GROUP; ++j) {
    int x = x0 + j;
    uint best = 0u, best_count = histogram[j] & 15u;
    [[unroll]] for (uint b = 1u; b < 8u; ++b) {
      uint count = (histogram[j] >> (4u * b)) & 15u;
      best = count > best_count ? b : best;
      best_count = max(best_count, count);
    }
    // Pixels on the border keep no label, so the clamped neighbours above never count.
    bool inside = x > 0 && y > 0 && x < pc.width - 1 && y < pc.height - 1;
    if (x < pc.width) {
      bool strong = float(magnitude[y * pc.width + x]) > pc.threshold_sq;
      labels[y * pc.width + x] = uint8_t(inside && strong && best_count >= 5u ? 1u << best : 0u);
    }
  }
}
