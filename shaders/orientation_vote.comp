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
  if (i >= pc.width * pc.height) return;
  int y = i / pc.width, x = i - y * pc.width;
  // The 3x3 histogram of bins as 4-bit counts in one word (at most 9 each): no per-lane
  // array indexing, which is a loop over the lanes on llvmpipe.
  bool inside = x > 0 && y > 0 && x < pc.width - 1 && y < pc.height - 1;
  uint histogram = 0u;
  for (int dy = -1; dy <= 1; ++dy)
    for (int dx = -1; dx <= 1; ++dx)
      histogram += 1u << (4u * uint(bins[clamp(i + dy * pc.width + dx, 0, pc.width * pc.height - 1)]));
  uint best = 0u, best_count = histogram & 15u;
  for (uint b = 1u; b < 8u; ++b) {
    uint count = (histogram >> (4u * b)) & 15u;
    best = count > best_count ? b : best;
    best_count = max(best_count, count);
  }
  uint label = inside && float(magnitude[i]) > pc.threshold_sq && best_count >= 5u ? 1u << best : 0u;
  labels[i] = uint8_t(label);
}
