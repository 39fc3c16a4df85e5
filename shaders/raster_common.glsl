// Shared by the template rasterizer's kernels; src/render/raster_math.hpp is the C++ twin and
// does the same float operations in the same order (`precise` keeps the compiler from fusing
// them), so the CPU reference renders the same pixels.
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require

layout(std430, binding = 0) readonly buffer Vertices { vec4 vertices[]; };
layout(std430, binding = 1) readonly buffer Faces { uvec4 faces[]; };
layout(std430, binding = 2) readonly buffer Poses { vec4 poses[]; };  // 3 rows (R | t) per view

layout(push_constant) uniform Push {
  float fx, fy, cx, cy;
  int width, height;
  uint face_count;
  uint flags;  // 1: per-vertex normals, 2: per-vertex colours
} pc;

const float kSubpixel = 8.0;      // fixed point: 1/8 pixel
const float kNearZ = 1e-3;        // metres: triangles closer than this are dropped
const float kGuardPx = 1048576.0; // screen coordinates beyond this are dropped

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
  vec4 r0 = poses[3u * view], r1 = poses[3u * view + 1u], r2 = poses[3u * view + 2u];
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

// One corner: camera point, 1 / z and the fixed-point screen position; false when it lies
// nearer than kNearZ or beyond the guard band (then the other outputs mean nothing).
bool projectCorner(uint view, uint vertex, out vec3 p, out float rz_out, out ivec2 s) {
  p = toCamera(view, vertices[vertex].xyz);
  precise float rz = 1.0 / p.z;
  precise float sx = pc.fx * (p.x * rz) + pc.cx;
  precise float sy = pc.fy * (p.y * rz) + pc.cy;
  rz_out = rz;
  s = ivec2(floor(sx * kSubpixel + 0.5), floor(sy * kSubpixel + 0.5));
  return p.z > kNearZ && abs(sx) < kGuardPx && abs(sy) < kGuardPx;
}

bool setupTriangle(uint view, uint f, out Triangle t) {
  uvec4 idx = faces[f];
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
  // Pixel centres sit on integer coordinates (OpenCV's convention): lo / 8 rounded up.
  t.box = ivec4(max(-floorDiv8(-lo.x), 0), max(-floorDiv8(-lo.y), 0), min(floorDiv8(hi.x), pc.width - 1),
                min(floorDiv8(hi.y), pc.height - 1));
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

// Depth where the pixel's ray meets the triangle's plane: exact, unaffected by the 1/8-pixel
// snapping that decides coverage; clamped to the triangle's own depth range for grazing
// triangles whose plane is nearly parallel to the ray.
float depthAt(Triangle t, int x, int y) {
  precise vec3 ray = vec3((float(x) - pc.cx) * (1.0 / pc.fx), (float(y) - pc.cy) * (1.0 / pc.fy), 1.0);
  precise float denom = dot(t.n, ray);
  precise float z = denom != 0.0 ? t.n_p0 * (1.0 / denom) : t.zrange.y;
  return clamp(z, t.zrange.x, t.zrange.y);
}
