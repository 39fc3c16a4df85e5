#version 450
// Template rendering, pass 1: every (triangle, view) writes (depth, triangle id) into the
// pixels it covers with a 64-bit atomicMin, so the nearest triangle wins (ties: lower id)
// without any ordering between invocations.
#extension GL_EXT_shader_atomic_int64 : require
#include "raster_common.glsl"
layout(local_size_x = kWorkgroupSize) in;
layout(std430, binding = 3) buffer Raster { uint64_t raster[]; };
void main() {
  uint f = gl_GlobalInvocationID.x;
  uint view = gl_WorkGroupID.y;
  usePrincipalPointOf(view);
  if (f >= pc.face_count) return;
  Triangle t;
  if (!setupTriangle(view, f, t)) return;
  uint base = view * uint(pc.width * pc.height);
  const ivec2 rows = bandRows(t.box);  // this invocation's share of the box's rows
  for (int y = rows.x; y <= rows.y; ++y)
    for (int x = t.box.x; x <= t.box.z; ++x) {
      vec3 e = edgesAt(t, x, y);
      if (e.x < 0.0 || e.y < 0.0 || e.z < 0.0) continue;
      float z = depthAt(t, x, y);
      // Positive floats order like their bit patterns.
      atomicMin(raster[base + uint(y * pc.width + x)], (uint64_t(floatBitsToUint(z)) << 32) | uint64_t(f));
    }
}
