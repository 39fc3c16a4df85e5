#version 450
// Stage 2, finer level: the scores of each unit (see refine_grid.glsl) of this chunk, BAND
// rows of 16 positions packed as scoreSixteen leaves them.
#include "similarity_common.glsl"
#include "refine_grid.glsl"
layout(local_size_x = 64) in;
layout(std430, binding = 3) readonly buffer Units { uint units[]; };
layout(std430, binding = 4) readonly buffer State { uint unit_count; };
layout(std430, binding = 5) writeonly buffer Scores { uvec4 scores[]; };
layout(push_constant) uniform Push { int stride; uint capacity; UnitGrid grid; } pc;
void main() {
  uint u = gl_GlobalInvocationID.y * 32768u * 64u + gl_GlobalInvocationID.x;
  if (u >= min(unit_count, pc.capacity)) return;
  int bit = int(units[u]);
  int per_band = pc.grid.words_per_band * 32;
  int t = bit / (pc.grid.bands * per_band);
  int rest = bit - t * pc.grid.bands * per_band;
  int row = (rest / per_band) * BAND - pc.grid.pad;
  int column = (rest % per_band) * 16 - pc.grid.pad;
  int h = t * HEADER_INTS;
  int f = headers[h], end = f + headers[h + 1];
  uint base = uint(row * pc.stride + column), stride = uint(pc.stride);
  uvec4 lo[BAND], hi[BAND];
  for (int r = 0; r < BAND; ++r) lo[r] = hi[r] = uvec4(0u);
  while (f < end) {
    int chunk_end = min(f + 63, end);
    uvec4 acc[BAND];
    for (int r = 0; r < BAND; ++r) acc[r] = uvec4(0u);
    for (; f < chunk_end; ++f) {
      uint off = uint(texelFetch(feature_offsets, f).x) + base;
      for (int r = 0; r < BAND; ++r) acc[r] += sixteenBytes(off + uint(r) * stride);
    }
    for (int r = 0; r < BAND; ++r) widen(acc[r], lo[r], hi[r]);
  }
  for (int r = 0; r < BAND; ++r) {
    scores[(u * uint(BAND) + uint(r)) * 2u] = lo[r];
    scores[(u * uint(BAND) + uint(r)) * 2u + 1u] = hi[r];
  }
}
