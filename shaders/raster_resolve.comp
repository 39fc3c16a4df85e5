#version 450
// Template rendering, pass 2: per pixel, the winning triangle's depth, normal (interpolated
// vertex normals, or the face normal) facing the camera, and colour (interpolated vertex
// colour, or grey shaded by a light at the camera).
#include "raster_common.glsl"
layout(local_size_x = kWorkgroupSize) in;
// Read through texel buffers (gathers on lavapipe), as the mesh in raster_common.glsl.
layout(binding = 3) uniform utextureBuffer raster_texels;   // pass 1's keys: low word, high word
layout(binding = 4) uniform utextureBuffer normal_texels;   // vertex normals, float bits
layout(binding = 5) uniform utextureBuffer colour_texels;   // vertex colours, packed
vec3 vertexNormal(uint v) { return uintBitsToFloat(texelFetch(normal_texels, int(v)).xyz); }
vec3 vertexColour(uint v) { return unpackUnorm4x8(texelFetch(colour_texels, int(v)).x).xyz; }
layout(std430, binding = 6) writeonly buffer Depth { float depth_out[]; };
layout(std430, binding = 7) writeonly buffer NormalOut { vec4 normal_out[]; };
layout(std430, binding = 8) writeonly buffer ColourOut { uint colour_out[]; };

uint packChannel(float c) { return uint(clamp(c, 0.0, 1.0) * 255.0 + 0.5); }

void main() {
  uint i = gl_GlobalInvocationID.x;
  uint view = gl_WorkGroupID.y;
  usePrincipalPointOf(view);
  uint pixels = uint(pc.width * pc.height);
  if (i >= pixels) return;
  uint o = view * pixels + i;
  const uvec2 words = texelFetch(raster_texels, int(o)).xy;
  const uint64_t key = (uint64_t(words.y) << 32) | uint64_t(words.x);
  if (key == ~uint64_t(0)) {
    depth_out[o] = 0.0;
    normal_out[o] = vec4(0.0);
    colour_out[o] = 0u;
    return;
  }
  if ((pc.flags & kRasterDepthOnly) != 0u) {  // no triangle to set up again
    depth_out[o] = uintBitsToFloat(uint(key >> 32));
    return;
  }
  uint f = uint(key & 0xFFFFFFFFul);
  int y = int(i) / pc.width, x = int(i) - y * pc.width;
  precise float z = uintBitsToFloat(uint(key >> 32));
  Triangle t;
  precise vec3 w;
  vec3 face_n;
  if (setupTriangle(view, f, t)) {
    vec3 e = edgesAt(t, x, y);
    precise float inv_area = 1.0 / t.area;
    w = vec3(e.x * inv_area * t.rz.x * z, e.y * inv_area * t.rz.y * z, e.z * inv_area * t.rz.z * z);
    face_n = t.n;
  } else {
    // A clipped face (raster_depth.comp): weights from its corners in the camera frame.
    precise vec3 point = vec3((float(x) - principal.x) * (1.0 / pc.camera.fx),
                              (float(y) - principal.y) * (1.0 / pc.camera.fy), 1.0) * z;
    w = faceWeights(view, f, point, face_n);
  }
  uvec4 idx = faceAt(f);
  precise vec3 n;
  if ((pc.flags & kRasterVertexNormals) != 0u) {
    precise vec3 m = w.x * vertexNormal(idx.x) + w.y * vertexNormal(idx.y) + w.z * vertexNormal(idx.z);
    vec4 r0 = poseRow(view, 0u), r1 = poseRow(view, 1u), r2 = poseRow(view, 2u);
    n = vec3(dot(r0.xyz, m), dot(r1.xyz, m), dot(r2.xyz, m));
  } else {
    n = face_n;
  }
  precise vec3 ray = vec3((float(x) - principal.x) / pc.camera.fx, (float(y) - principal.y) / pc.camera.fy, 1.0);
  precise float len2 = dot(n, n);
  if (len2 > 0.0) n = n * (1.0 / sqrt(len2));
  if (dot(n, ray) > 0.0) n = -n;
  vec3 bgr;
  if ((pc.flags & kRasterVertexColours) != 0u) {
    precise vec3 c = w.x * vertexColour(idx.x) + w.y * vertexColour(idx.y) + w.z * vertexColour(idx.z);
    bgr = c;
  } else {
    precise float lambert = max(0.0, -dot(n, ray) * (1.0 / sqrt(dot(ray, ray))));
    bgr = vec3(0.25 + 0.65 * lambert);
  }
  depth_out[o] = z;
  normal_out[o] = vec4(n, 0.0);
  colour_out[o] = packChannel(bgr.x) | (packChannel(bgr.y) << 8) | (packChannel(bgr.z) << 16);
}
