#version 450
// Indirect dispatch sizes of a chunk's refinement, as 2D grids of at most 32768 columns of
// 64 invocations. After the chunk's coarse pass (stage 0): its candidates are those appended
// since the previous chunk, one invocation each for marking and selection. After its units
// are numbered (stage 1): one invocation per listed run, per run length.
#include "refine_grid.glsl"
layout(local_size_x = 1) in;
layout(std430, binding = 0) readonly buffer Candidates { uint count; };
layout(std430, binding = 1) buffer State { REFINE_STATE };
layout(push_constant) uniform ArgsPushBlock { ArgsPush pc; };
uvec4 grid(uint invocations) {
  uint n = (invocations + kWorkgroupSize - 1u) / kWorkgroupSize;
  return uvec4(max(min(n, kGridColumns), 1u), (n + kGridColumns - 1u) / kGridColumns, 1u, 0u);
}
void main() {
  // Once the pass has overflowed the candidate list or a chunk's units, it is read back only
  // for its counts and run again (Similarity::read): the refinement of the chunks after that
  // is skipped (zero-sized dispatches), so a pass that finds the sizes costs about its
  // coarse level. The counts go on: the candidates' from each coarse pass, the units' from
  // every chunk whose candidates were all listed.
  bool overflowed = count > pc.candidate_capacity || max_units > pc.unit_capacity;
  if (pc.stage == 0u) {
    uint end = min(count, pc.candidate_capacity);
    first_candidate = next_candidate;
    next_candidate = end;
    candidate_groups = grid(overflowed ? 0u : end - first_candidate);
  } else {
    max_units = max(max_units, unit_count);
    overflowed = overflowed || max_units > pc.unit_capacity;
    for (int span = 1; span <= kMaxSpan; ++span)
      run_groups[span - 1] = grid(overflowed ? 0u : min(run_count[span - 1], runCapacity(pc.unit_capacity, span)));
    if (overflowed) candidate_groups = grid(0u);  // nor selected
  }
}
