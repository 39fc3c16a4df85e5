#version 450
// Indirect dispatch sizes of a chunk's refinement, as 2D grids of at most 32768 columns of
// 64 invocations. After the chunk's coarse pass (stage 0): its candidates are those appended
// since the previous chunk, one invocation each for marking and selection. After its units
// are numbered (stage 1): one invocation per unit for scoring.
layout(local_size_x = 1) in;
layout(std430, binding = 0) readonly buffer Candidates { uint count; };
layout(std430, binding = 1) buffer State {
  uint unit_count;       // this chunk's units (reset before each chunk)
  uint max_units;        // most units of any chunk: more than the capacity means run again
  uint next_candidate;   // first candidate of the next chunk
  uint first_candidate;  // first candidate of this chunk
  uvec4 candidate_groups;  // byte 16
  uvec4 unit_groups;       // byte 32
};
layout(push_constant) uniform Push { uint stage; uint unit_capacity; uint candidate_capacity; } pc;
uvec4 grid(uint invocations) {
  uint n = (invocations + 63u) / 64u;
  return uvec4(max(min(n, 32768u), 1u), (n + 32767u) / 32768u, 1u, 0u);
}
void main() {
  if (pc.stage == 0u) {
    uint end = min(count, pc.candidate_capacity);
    first_candidate = next_candidate;
    next_candidate = end;
    candidate_groups = grid(end - first_candidate);
  } else {
    max_units = max(max_units, unit_count);
    unit_groups = grid(min(unit_count, pc.unit_capacity));
  }
}
