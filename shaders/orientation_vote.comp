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
  uint label = 0u;
  if (x > 0 && y > 0 && x < pc.width - 1 && y < pc.height - 1 && float(magnitude[i]) > pc.threshold_sq) {
    int histogram[8] = int[](0, 0, 0, 0, 0, 0, 0, 0);
    for (int dy = -1; dy <= 1; ++dy)
      for (int dx = -1; dx <= 1; ++dx) histogram[int(bins[i + dy * pc.width + dx])]++;
    int best = 0;
    for (int b = 1; b < 8; ++b)
      if (histogram[b] > histogram[best]) best = b;
    if (histogram[best] >= 5) label = 1u << best;
  }
  labels[i] = uint8_t(label);
}
