#version 450
// Numbers the units marked by refine_mark.comp: each non-zero mark word gets a range
// of unit slots (the order across words does not matter) and lists its units' bits.
layout(local_size_x = 64) in;
layout(std430, binding = 0) readonly buffer Marks { uint marks[]; };
layout(std430, binding = 1) writeonly buffer Bases { uint bases[]; };
layout(std430, binding = 2) writeonly buffer Units { uint units[]; };
layout(std430, binding = 3) buffer State { uint unit_count; };
layout(push_constant) uniform Push { uint words; uint capacity; } pc;
void main() {
  uint i = gl_GlobalInvocationID.y * 32768u * 64u + gl_GlobalInvocationID.x;
  if (i >= pc.words) return;
  uint m = marks[i];
  if (m == 0u) return;
  uint base = atomicAdd(unit_count, uint(bitCount(m)));
  bases[i] = base;
  for (; m != 0u; m &= m - 1u, ++base)
    if (base < pc.capacity) units[base] = i * 32u + uint(findLSB(m));
}
