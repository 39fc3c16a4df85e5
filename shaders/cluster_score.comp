#version 450
// Stage 4, the cluster score: one invocation compares one member template's depth and
// normal crop with the scene at the hypothesis's centre (two passes: the mean depth offset,
// then the truncated depth error and the normal angle). The GLSL twin of scoreMember in
// src/hypotheses/cluster_score_math.hpp: same operations in the same order.
#include "gpu/kernel_interface.h"
layout(local_size_x = kWorkgroupSize) in;
layout(binding = 0) uniform utextureBuffer cells;    // rg32ui: depth in 0.1 mm, 3 int8 normals
layout(binding = 1) uniform utextureBuffer members;  // rgba32ui, 4 texels per member
layout(binding = 2) uniform utextureBuffer depth;    // r32ui: float metres, row-major
layout(std430, binding = 3) buffer Scores { uvec4 scores[]; };  // 2 per member
// The scene's normal at each pixel, computed once a frame by scene_normals.comp (sceneNormal's
// result: x, y, z as float bits, w 1 where there is one); per member cell it cost five depth
// fetches and a cross product.
layout(binding = 4) uniform utextureBuffer scene_normals;
layout(push_constant) uniform ScorePushBlock { ScorePush pc; };

#include "scene_normal.glsl"

vec3 cellNormal(uint packed) {
  return vec3(float(bitfieldExtract(int(packed), 0, 8)), float(bitfieldExtract(int(packed), 8, 8)),
              float(bitfieldExtract(int(packed), 16, 8)));
}

void main() {
  uint m = gl_GlobalInvocationID.x + gl_GlobalInvocationID.y * gl_NumWorkGroups.x * gl_WorkGroupSize.x;
  if (m >= pc.member_count) return;
  uvec4 r0 = texelFetch(members, int(4u * m));
  uvec4 r1 = texelFetch(members, int(4u * m + 1u));
  uvec4 r2 = texelFetch(members, int(4u * m + 2u));
  uvec4 r3 = texelFetch(members, int(4u * m + 3u));
  int first = int(r0.x), cols = int(r0.y & 0xFFFFu), rows = int(r0.y >> 16), stride = int(r0.z);
  int x0 = int(r1.x), y0 = int(r1.y);
  mat3 ray = mat3(uintBitsToFloat(uvec3(r1.z, r2.y, r3.x)),   // column 0: R00 R10 R20
                  uintBitsToFloat(uvec3(r1.w, r2.z, r3.y)),   // column 1
                  uintBitsToFloat(uvec3(r2.x, r2.w, r3.z)));  // column 2

  int object_cells = 0, depth_pairs = 0, normal_pairs = 0;
  precise float offset_sum = 0.0;
  for (int i = 0; i < rows; ++i)
    for (int j = 0; j < cols; ++j) {
      uint dt = texelFetch(cells, first + i * cols + j).x;
      if (dt == 0u) continue;
      ++object_cells;
      float ds = sceneDepth(x0 + j * stride, y0 + i * stride);
      if (ds <= 0.0) continue;
      ++depth_pairs;
      offset_sum += ds - float(dt) * 1e-4;
    }
  precise float offset = 0.0, error_sum = 0.0, angle_sum = 0.0;
  if (depth_pairs > 0) {
    offset = offset_sum / float(depth_pairs);
    for (int i = 0; i < rows; ++i)
      for (int j = 0; j < cols; ++j) {
        uvec2 cell = texelFetch(cells, first + i * cols + j).xy;
        if (cell.x == 0u) continue;
        int x = x0 + j * stride, y = y0 + i * stride;
        float ds = sceneDepth(x, y);
        if (ds <= 0.0) continue;
        error_sum += min(abs(ds - float(cell.x) * 1e-4 - offset), pc.depth_cap);
        const uvec4 scene_normal = texelFetch(scene_normals, y * pc.width + x);
        if (scene_normal.w == 0u) continue;
        const vec3 ns = uintBitsToFloat(scene_normal.xyz);
        vec3 nt = normalize(ray * cellNormal(cell.y));
        angle_sum += acos(clamp(dot(nt, ns), -1.0, 1.0));
        ++normal_pairs;
      }
  }
  float error = depth_pairs > 0 ? error_sum / float(depth_pairs) : 0.0;
  float angle = normal_pairs > 0 ? angle_sum / float(normal_pairs) : 0.0;
  scores[2u * m] = uvec4(uint(object_cells), uint(depth_pairs), uint(normal_pairs), 0u);
  scores[2u * m + 1u] = uvec4(floatBitsToUint(offset), floatBitsToUint(error), floatBitsToUint(angle), 0u);
}
