#version 450
// Template rendering, pass 1 for the triangles raster_depth.comp leaves out because a corner
// lies at kNearZ or nearer (a floor or a wall reaching past the camera): each is clipped at
// kClipZ and its part in front written as raster_depth.comp writes a triangle. A pass of its
// own, dispatched only when the mesh reaches past the camera in some view of the batch
// (src/render/renderer.cpp): inside raster_depth.comp the clipping code slowed every render
// on lavapipe by about two thirds (`bench train --views 60`, render 1.0-1.2 -> 1.7-1.9 s,
// 2026-11-28).
#extension GL_EXT_shader_atomic_int64 : require
#include "raster_common.glsl"
layout(local_size_x = kWorkgroupSize) in;
layout(std430, binding = 3) buffer Raster { uint64_t raster[]; };
void main() {
  uint f = gl_GlobalInvocationID.x;
  uint view = gl_WorkGroupID.y;
  usePrincipalPointOf(view);
  if (f >= pc.face_count) return;
  ClippedFace c;
  if (!clipFace(view, f, c)) return;
  uint base = view * uint(pc.width * pc.height);
  const ivec2 rows = bandRows(c.box);
  for (int y = rows.x; y <= rows.y; ++y)
    for (int x = c.box.x; x <= c.box.z; ++x) {
      if (!insideClipped(c, x, y)) continue;
      float z = planeDepthAt(c.n, c.n_p0, c.zrange, x, y);
      // Positive floats order like their bit patterns.
      atomicMin(raster[base + uint(y * pc.width + x)], (uint64_t(floatBitsToUint(z)) << 32) | uint64_t(f));
    }
}
