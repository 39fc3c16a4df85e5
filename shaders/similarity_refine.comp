#version 450
// Stage 2, finer level: the scores of each unit (see refine_grid.glsl) of this chunk, kUnitBand
// rows of 16 positions packed as packed_scores.glsl reads them. An invocation scores a run of
// SPAN neighbouring units (refine_units.comp): a row of them takes TEXELS fetches of 32
// nibbles per feature.
#include "similarity_common.glsl"
#include "refine_grid.glsl"
layout(constant_id = 0) const int SPAN = 1;
const int TEXELS = TEXELS_FOR(16 * SPAN);
layout(local_size_x = kWorkgroupSize) in;
layout(std430, binding = 3) readonly buffer Runs { uvec4 runs[]; };  // template band, padded column, slot
layout(std430, binding = 4) readonly buffer State { REFINE_STATE };
layout(std430, binding = 5) writeonly buffer Scores { uvec4 scores[]; };
layout(push_constant) uniform RefinePushBlock { RefinePush pc; };

void main() {
  uint u = gl_GlobalInvocationID.y * kGridColumns * kWorkgroupSize + gl_GlobalInvocationID.x;
  if (u >= min(run_count[SPAN - 1], runCapacity(pc.capacity, SPAN))) return;
  uvec4 run = runs[runRegion(pc.capacity, SPAN) + u];
  uint slot = run.z;
  if (slot + uint(SPAN) > pc.capacity) return;
  int t = int(run.x) / pc.grid.bands;
  int row = (int(run.x) - t * pc.grid.bands) * kUnitBand - pc.grid.pad;
  int column = int(run.y) - pc.grid.pad;
  int h = t * kHeaderInts;
  int f = header(h), end = f + header(h + 1);
  uint base = uint(row * pc.stride + column);
  int row_texels = pc.stride / 32;
  uvec4 lo[kUnitBand * SPAN], hi[kUnitBand * SPAN];
  for (int i = 0; i < kUnitBand * SPAN; ++i) lo[i] = hi[i] = uvec4(0u);
  while (f < end) {
    int chunk_end = min(f + kFeaturesPer8Bit, end);
    uvec4 acc[kUnitBand * SPAN];
    for (int i = 0; i < kUnitBand * SPAN; ++i) acc[i] = uvec4(0u);
    for (; f < chunk_end; ++f) {
      // Nibble offset of the run's first position for this feature.
      int first;
      uint q, s;
      nibbleAddress(uint(texelFetch(feature_offsets, f).x) + base, first, q, s);
      for (int r = 0; r < kUnitBand; ++r) ADD_ROW_BLOCKS(acc, r * SPAN, first + r * row_texels, q, s)
    }
    for (int i = 0; i < kUnitBand * SPAN; ++i) widenSplit(acc[i], lo[i], hi[i]);
  }
  for (int k = 0; k < SPAN; ++k)
    for (int r = 0; r < kUnitBand; ++r) {
      scores[((slot + uint(k)) * uint(kUnitBand) + uint(r)) * 2u] = lo[r * SPAN + k];
      scores[((slot + uint(k)) * uint(kUnitBand) + uint(r)) * 2u + 1u] = hi[r * SPAN + k];
    }
}
