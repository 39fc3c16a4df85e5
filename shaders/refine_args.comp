#version 450
// Indirect dispatch size for refinement: one invocation per stored candidate, workgroups of
// 32, as a 2D grid of at most 32768 columns.
layout(local_size_x = 1) in;
layout(std430, binding = 0) readonly buffer Candidates { uint count; uint pad0; uint pad1; uint pad2; };
layout(std430, binding = 1) writeonly buffer Args { uint groups[3]; };
layout(push_constant) uniform Push { uint capacity; } pc;
void main() {
  uint n = (min(count, pc.capacity) + 31u) / 32u;
  groups[0] = max(min(n, 32768u), 1u);
  groups[1] = (n + 32767u) / 32768u;
  groups[2] = 1u;
}
