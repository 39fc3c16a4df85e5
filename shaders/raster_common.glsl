// Shared by the template rasterizer's kernels; src/render/raster_math.hpp is the C++ twin and
// does the same float operations in the same order (`precise` keeps the compiler from fusing
// them), so the CPU reference renders the same pixels.
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require
#include "gpu/kernel_interface.h"

// The mesh and the poses in texel buffers: on lavapipe a texel fetch is one gather where a storage-buffer
// load at a per-invocation offset is a loop over the lanes, and a triangle's setup (four such
// loads) is nearly all of the raster pass's time.
layout(binding = 0) uniform utextureBuffer vertex_texels;  // x, y, z as float bits, 0
layout(binding = 1) uniform utextureBuffer face_texels;    // corner indices a, b, c, 0
vec3 vertexAt(uint v) { return uintBitsToFloat(texelFetch(vertex_texels, int(v)).xyz); }
uvec4 faceAt(uint f) { return texelFetch(face_texels, int(f)); }
// Per view 4 texels: the rows of R | t, then the view's principal point (cx, cy): views of one
// batch may each see through their own window of a frame (MeshRenderer::render's cameras).
layout(binding = 2) uniform utextureBuffer pose_texels;
vec4 poseRow(uint view, uint row) { return uintBitsToFloat(texelFetch(pose_texels, int(4u * view + row))); }

// The principal point of the view this invocation renders: each kernel's main() sets it first.
vec2 principal;
void usePrincipalPointOf(uint view) { principal = poseRow(view, 3u).xy; }

layout(push_constant) uniform RasterPushBlock { RasterPush pc; };

// Edge functions are exact integers. In 32 bits when the triangle spans less than
// kNarrowExtent in x and y: every difference is then below 2^14 and every product below 2^28
// (pixels tested lie in the triangle's box). Wider triangles (2,048 px and more) take 64 bits.
// The two give the same integers; lavapipe runs 64-bit integer vectors lane by lane (with the
// corners in 32 bits too, a stage-6 window of a 62k-face mesh 13.6 -> 9.7 ms).
const int kNarrowExtent = 16384;  // fixed point: 2,048 px

struct Triangle {
  ivec2 s0, s1, s2; // screen, fixed point (within the guard band: below 2^23)
  bool wide;        // spans kNarrowExtent or more: edge functions in 64 bits
  float area;       // twice the signed area, fixed point, made positive (an integer)
  float sign;       // +1 or -1: the winding
  ivec4 box;        // inclusive pixel bounds, clipped to the image
  vec3 rz;          // 1 / z per vertex
  vec3 n;           // plane normal (unnormalized), camera frame
  float n_p0;       // dot(n, the first corner)
  vec2 zrange;      // nearest and farthest vertex depth
};

vec3 toCamera(uint view, vec3 v) {
  vec4 r0 = poseRow(view, 0u), r1 = poseRow(view, 1u), r2 = poseRow(view, 2u);
  precise vec3 c = vec3(dot(r0.xyz, v) + r0.w, dot(r1.xyz, v) + r1.w, dot(r2.xyz, v) + r2.w);
  return c;
}

int floorDiv8(int a) { return a >= 0 ? a / 8 : -((-a + 7) / 8); }

// The edge function as a float: the integer's sign and its rounding to float are those of
// the 64-bit value the C++ twin computes.
float edgeFunction(bool wide, ivec2 a, ivec2 b, ivec2 p) {
  if (wide)
    return float(int64_t(b.x - a.x) * int64_t(p.y - a.y) - int64_t(b.y - a.y) * int64_t(p.x - a.x));
  return float((b.x - a.x) * (p.y - a.y) - (b.y - a.y) * (p.x - a.x));
}

// A camera point's 1 / z and fixed-point screen position; false beyond the guard band (then
// the outputs mean nothing). Triangles and clipped faces round their corners alike.
bool projectPoint(vec3 p, out float rz_out, out ivec2 s) {
  precise float rz = 1.0 / p.z;
  precise float sx = pc.camera.fx * (p.x * rz) + principal.x;
  precise float sy = pc.camera.fy * (p.y * rz) + principal.y;
  rz_out = rz;
  s = ivec2(floor(sx * kSubpixel + 0.5), floor(sy * kSubpixel + 0.5));
  return abs(sx) < kGuardPx && abs(sy) < kGuardPx;
}

// One corner: camera point, 1 / z and the fixed-point screen position; false when it lies
// nearer than kNearZ or beyond the guard band (then the other outputs mean nothing).
bool projectCorner(uint view, uint vertex, out vec3 p, out float rz_out, out ivec2 s) {
  p = toCamera(view, vertexAt(vertex));
  const bool on_screen = projectPoint(p, rz_out, s);
  return p.z > kNearZ && on_screen;
}

// Inclusive pixel bounds of fixed-point corners from lo to hi, clipped to the image. Pixel
// centres sit on integer coordinates (OpenCV's convention): lo / 8 rounded up.
ivec4 pixelBox(ivec2 lo, ivec2 hi) {
  return ivec4(max(-floorDiv8(-lo.x), 0), max(-floorDiv8(-lo.y), 0), min(floorDiv8(hi.x), pc.width - 1),
               min(floorDiv8(hi.y), pc.height - 1));
}

bool setupTriangle(uint view, uint f, out Triangle t) {
  uvec4 idx = faceAt(f);
  t.area = 0.0;
  t.sign = 1.0;
  t.box = ivec4(0, 0, -1, -1);
  // Three calls, not a loop with early returns over the struct's arrays: on lavapipe that loop
  // was most of the setup's cost (an 8 x 8 window of a 62k-face mesh 14 -> 8 ms).
  vec3 p0, p1, p2;
  float rz0, rz1, rz2;
  ivec2 s0, s1, s2;
  const bool ok0 = projectCorner(view, idx.x, p0, rz0, s0);
  const bool ok1 = projectCorner(view, idx.y, p1, rz1, s1);
  const bool ok2 = projectCorner(view, idx.z, p2, rz2, s2);
  if (!(ok0 && ok1 && ok2)) return false;
  t.rz = vec3(rz0, rz1, rz2);
  t.s0 = s0;
  t.s1 = s1;
  t.s2 = s2;
  const ivec2 lo = min(s0, min(s1, s2)), hi = max(s0, max(s1, s2));
  t.wide = hi.x - lo.x >= kNarrowExtent || hi.y - lo.y >= kNarrowExtent;
  const float area = edgeFunction(t.wide, s0, s1, s2);
  if (area == 0.0) return false;
  precise vec3 n = cross(p1 - p0, p2 - p0);
  precise float n_p0 = dot(n, p0);
  t.n = n;
  t.n_p0 = n_p0;
  t.zrange = vec2(min(p0.z, min(p1.z, p2.z)), max(p0.z, max(p1.z, p2.z)));
  t.sign = area > 0.0 ? 1.0 : -1.0;
  t.area = area * t.sign;
  t.box = pixelBox(lo, hi);
  return t.box.x <= t.box.z && t.box.y <= t.box.w;
}

// Screen-space barycentric numerators at pixel (x, y) of the triangle's box, as floats; all
// >= 0 inside (edges included).
vec3 edgesAt(Triangle t, int x, int y) {
  ivec2 p = ivec2(x * 8, y * 8);
  return vec3(edgeFunction(t.wide, t.s1, t.s2, p), edgeFunction(t.wide, t.s2, t.s0, p),
              edgeFunction(t.wide, t.s0, t.s1, p)) *
         t.sign;
}

// Depth where the pixel's ray meets the plane (n, n_p0): exact, unaffected by the 1/8-pixel
// snapping that decides coverage; clamped to the face's own depth range for grazing faces
// whose plane is nearly parallel to the ray.
float planeDepthAt(vec3 n, float n_p0, vec2 zrange, int x, int y) {
  precise vec3 ray = vec3((float(x) - principal.x) * (1.0 / pc.camera.fx),
                          (float(y) - principal.y) * (1.0 / pc.camera.fy), 1.0);
  precise float denom = dot(n, ray);
  precise float z = denom != 0.0 ? n_p0 * (1.0 / denom) : zrange.y;
  return clamp(z, zrange.x, zrange.y);
}

float depthAt(Triangle t, int x, int y) { return planeDepthAt(t.n, t.n_p0, t.zrange, x, y); }

// A face with a corner at kNearZ or nearer (setupTriangle refuses it), cut by the plane
// z = kClipZ: the part in front, a convex polygon of 3 or 4 corners in the face's winding.
// Rare (a floor or a wall reaching past the camera), so kept apart from the triangle path.
struct ClippedFace {
  ivec2 s[4];    // screen, fixed point
  int count;     // 3 or 4
  bool wide;     // spans kNarrowExtent or more: edge functions in 64 bits
  float sign;    // +1 or -1: the winding
  ivec4 box;     // inclusive pixel bounds, clipped to the image
  vec3 n;        // the face's plane normal (unnormalized), camera frame
  float n_p0;
  vec2 zrange;   // nearest and farthest corner depth of the polygon
};

// False when no corner lies at kNearZ or nearer (setupTriangle's case), when nothing is left
// in front of kClipZ, or when a corner of what is left falls beyond the guard band.
bool clipFace(uint view, uint f, out ClippedFace c) {
  c.count = 0;
  c.wide = false;
  c.sign = 1.0;
  c.box = ivec4(0, 0, -1, -1);
  uvec4 idx = faceAt(f);
  vec3 p[3] = vec3[3](toCamera(view, vertexAt(idx.x)), toCamera(view, vertexAt(idx.y)),
                      toCamera(view, vertexAt(idx.z)));
  if (!(p[0].z <= kNearZ || p[1].z <= kNearZ || p[2].z <= kNearZ)) return false;
  precise vec3 n = cross(p[1] - p[0], p[2] - p[0]);
  precise float n_p0 = dot(n, p[0]);
  c.n = n;
  c.n_p0 = n_p0;
  vec3 q[4];
  int m = 0;
  for (int i = 0; i < 3; ++i) {
    vec3 a = p[i], b = p[i == 2 ? 0 : i + 1];
    if (a.z > kClipZ) q[m++] = a;
    if ((a.z > kClipZ) != (b.z > kClipZ)) {
      precise float k = (kClipZ - a.z) / (b.z - a.z);
      precise vec3 r = a + (b - a) * k;
      q[m++] = vec3(r.xy, kClipZ);
    }
  }
  if (m < 3) return false;
  c.count = m;
  c.zrange = vec2(kClipZ, kClipZ);
  ivec2 lo = ivec2(2147483647), hi = ivec2(-2147483647);
  for (int i = 0; i < m; ++i) {
    float rz;
    if (!projectPoint(q[i], rz, c.s[i])) return false;
    lo = min(lo, c.s[i]);
    hi = max(hi, c.s[i]);
    c.zrange.y = max(c.zrange.y, q[i].z);
  }
  c.wide = hi.x - lo.x >= kNarrowExtent || hi.y - lo.y >= kNarrowExtent;
  // Twice the signed area (the shoelace sum, exact in 64 bits) gives the winding.
  int64_t area = 0;
  for (int i = 0; i < m; ++i) {
    ivec2 a = c.s[i], b = c.s[i + 1 == m ? 0 : i + 1];
    area += int64_t(a.x) * int64_t(b.y) - int64_t(b.x) * int64_t(a.y);
  }
  if (area == 0) return false;
  c.sign = area > 0 ? 1.0 : -1.0;
  c.box = pixelBox(lo, hi);
  return c.box.x <= c.box.z && c.box.y <= c.box.w;
}

// Pixel (x, y) lies in the clipped face (edges included). No loop over the edges: lavapipe
// counts every iteration of every loop against an invocation's 65,535 (rasterBands), and a
// loop per pixel would cut a large face short.
bool insideClipped(ClippedFace c, int x, int y) {
  ivec2 p = ivec2(x * 8, y * 8);
  ivec2 s3 = c.count == 4 ? c.s[3] : c.s[0];  // a triangle's third edge closes at s[0]
  return edgeFunction(c.wide, c.s[0], c.s[1], p) * c.sign >= 0.0 &&
         edgeFunction(c.wide, c.s[1], c.s[2], p) * c.sign >= 0.0 &&
         edgeFunction(c.wide, c.s[2], s3, p) * c.sign >= 0.0 &&
         (c.count == 3 || edgeFunction(c.wide, s3, c.s[0], p) * c.sign >= 0.0);
}

// The rows of `box` that this invocation rasterizes: the box's rows are shared among the
// dispatch's z groups, one band each, because lavapipe ends an invocation's loops after
// 65,535 iterations in all, which cut off the lower rows of a face whose box held more
// pixels (src/render/renderer.cpp, rasterBands).
ivec2 bandRows(ivec4 box) {
  const int bands = int(gl_NumWorkGroups.z), rows = (box.w - box.y + bands) / bands;
  const int y0 = box.y + int(gl_WorkGroupID.z) * rows;
  return ivec2(y0, min(box.w, y0 + rows - 1));
}

// Perspective-correct weights of the face's corners at the camera point `point` on its plane,
// from the corners' camera points: for clipped faces, whose own screen corners are not the
// face's.
vec3 faceWeights(uint view, uint f, vec3 point, out vec3 n_out) {
  uvec4 idx = faceAt(f);
  vec3 p0 = toCamera(view, vertexAt(idx.x)), p1 = toCamera(view, vertexAt(idx.y)),
       p2 = toCamera(view, vertexAt(idx.z));
  precise vec3 n = cross(p1 - p0, p2 - p0);
  precise float inv = 1.0 / dot(n, n);
  precise float w0 = dot(cross(p1 - point, p2 - point), n) * inv;
  precise float w1 = dot(cross(p2 - point, p0 - point), n) * inv;
  n_out = n;
  return vec3(w0, w1, 1.0 - w0 - w1);
}
