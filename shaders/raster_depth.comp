#version 450
// Template rendering, pass 1: every (triangle, view) writes (depth, triangle id) into the
// pixels it covers with a 64-bit atomicMin, so the nearest triangle wins (ties: lower id)
// without any ordering between invocations.
#extension GL_EXT_shader_atomic_int64 : require
#include "raster_common.glsl"
layout(local_size_x = 64) in;
layout(std430, binding = 3) buffer Raster { uint64_t raster[]; };
void main() {
  uint f = gl_GlobalInvocationID.x;
  uint view = gl_WorkGroupID.y;
  if (f >= pc.face_count) return;
  Triangle t;
  if (!setupTriangle(view, f, t)) return;
  uint base = view * uint(pc.width * pc.height);
  // The box's rows are shared among the dispatch's z groups, each invocation taking one band:
  // lavapipe ends an invocation's loops after 65,535 iterations in all, which cut off the
  // lower rows of a triangle whose box held more pixels (src/render/renderer.cpp, rasterBands).
  const int bands = int(gl_NumWorkGroups.z), rows = (t.box.w - t.box.y + bands) / bands;
  const int y0 = t.box.y + int(gl_WorkGroupID.z) * rows, y1 = min(t.box.w, y0 + rows - 1);
  for (int y = y0; y <= y1; ++y)
    for (int x = t.box.x; x <= t.box.z; ++x) {
      vec3 e = edgesAt(t, x, y);
      if (e.x < 0.0 || e.y < 0.0 || e.z < 0.0) continue;
      float z = depthAt(t, x, y);
      // Positive floats order like their bit patterns.
      atomicMin(raster[base + uint(y * pc.width + x)], (uint64_t(floatBitsToUint(z)) << 32) | uint64_t(f));
    }
}
