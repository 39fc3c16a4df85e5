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
  int i = LINEAR_INVOCATION;
  if (i >= pc.width * pc.height) return;
  int y = i / pc.width, x = i - y * pc.width;
  uint s = uint(spread[i]);
  uint plane = uint(pc.stride * pc.rows);
  uint cell = uint((y / pc.T + pc.pad) * pc.stride + x / pc.T + pc.pad);
  for (int b = 0; b < 8; ++b) {
    // Rotate the label set so that bin b is bit 0; bins d away are then bits d and 8 - d.
    uint r = ((s >> b) | (s << (8 - b))) & 0xFFu;
    int best = (r & 1u) != 0u ? 4 : (r & 0x82u) != 0u ? 3 : (r & 0x44u) != 0u ? 2 : (r & 0x28u) != 0u ? 1 : 0;
    uint grid = uint(((pc.modality * 8 + b) * pc.T + y % pc.T) * pc.T + x % pc.T);
    memory[grid * plane + cell] = uint8_t(best);
  }
}
