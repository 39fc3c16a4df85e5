#version 450
// Response maps (quantized cosine: 4 - circular bin distance to the nearest spread
// orientation) written straight into the padded linear memories of one modality.
#include "common.glsl"
layout(local_size_x = 64) in;
layout(std430, binding = 0) readonly buffer Spread { uint8_t spread[]; };
layout(std430, binding = 1) writeonly buffer Memory { uint8_t memory[]; };
layout(push_constant) uniform Push {
  int width; int height; int T; int pad; int stride; int rows; int modality;
} pc;
void main() {
  int i = int(gl_GlobalInvocationID.x);
  if (i >= pc.width * pc.height) return;
  int y = i / pc.width, x = i - y * pc.width;
  uint s = uint(spread[i]);
  uint plane = uint(pc.stride * pc.rows);
  uint cell = uint((y / pc.T + pc.pad) * pc.stride + x / pc.T + pc.pad);
  for (int b = 0; b < 8; ++b) {
    int best = 0;
    for (int j = 0; j < 8; ++j) {
      if ((s & (1u << j)) == 0u) continue;
      int d = abs(b - j);
      best = max(best, 4 - min(d, 8 - d));
    }
    uint grid = uint(((pc.modality * 8 + b) * pc.T + y % pc.T) * pc.T + x % pc.T);
    memory[grid * plane + cell] = uint8_t(best);
  }
}
