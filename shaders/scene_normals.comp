#version 450
// Stage 4, once a frame: the scene's normal at every pixel (sceneNormal, scene_normal.glsl),
// which cluster_score.comp reads at each member's cells instead of computing it again there.
#include "gpu/kernel_interface.h"
layout(local_size_x = kWorkgroupSize) in;
layout(binding = 0) uniform utextureBuffer depth;  // r32ui: float metres, row-major
layout(std430, binding = 1) writeonly buffer Normals { uvec4 normals[]; };  // x, y, z float bits; w: 1 where there is one
layout(push_constant) uniform ScorePushBlock { ScorePush pc; };
#include "scene_normal.glsl"
void main() {
  uint i = gl_GlobalInvocationID.x + gl_GlobalInvocationID.y * gl_NumWorkGroups.x * gl_WorkGroupSize.x;
  if (i >= uint(pc.width) * uint(pc.height)) return;
  int y = int(i) / pc.width, x = int(i) - y * pc.width;
  vec3 n;
  const bool found = sceneNormal(x, y, n);
  normals[i] = uvec4(floatBitsToUint(n), found ? 1u : 0u);
}
