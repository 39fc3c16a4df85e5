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

struct Triangle {
  vec3 p[3];        // camera frame, metres
  i64vec2 s[3];     // screen, fixed point
  int64_t area;     // twice the signed area, fixed point, made positive
  int64_t sign;     // +1 or -1: the winding
  ivec4 box;        // inclusive pixel bounds, clipped to the image
  float rz[3];      // 1 / z per vertex
  vec3 n;           // plane normal (unnormalized), camera frame
  float n_p0;       // dot(n, p[0])
  vec2 zrange;      // nearest and farthest vertex depth
};

vec3 toCamera(uint view, vec3 v) {
  vec4 r0 = poses[3u * view], r1 = poses[3u * view + 1u], r2 = poses[3u * view + 2u];
  precise vec3 c = vec3(dot(r0.xyz, v) + r0.w, dot(r1.xyz, v) + r1.w, dot(r2.xyz, v) + r2.w);
  return c;
}

int64_t floorDiv8(int64_t a) { return a >= 0 ? a / 8 : -((-a + 7) / 8); }

int64_t edgeFunction(i64vec2 a, i64vec2 b, i64vec2 p) {
  return (b.x - a.x) * (p.y - a.y) - (b.y - a.y) * (p.x - a.x);
}

bool setupTriangle(uint view, uint f, out Triangle t) {
  uvec4 idx = faces[f];
  t.area = 0;
  t.sign = 1;
  t.box = ivec4(0, 0, -1, -1);
  for (int i = 0; i < 3; ++i) {
    t.p[i] = toCamera(view, vertices[idx[i]].xyz);
    if (!(t.p[i].z > kNearZ)) return false;
    precise float rz = 1.0 / t.p[i].z;
    precise float sx = pc.fx * (t.p[i].x * rz) + pc.cx;
    precise float sy = pc.fy * (t.p[i].y * rz) + pc.cy;
    if (!(abs(sx) < kGuardPx && abs(sy) < kGuardPx)) return false;
    t.rz[i] = rz;
    t.s[i] = i64vec2(int64_t(floor(sx * kSubpixel + 0.5)), int64_t(floor(sy * kSubpixel + 0.5)));
  }
  int64_t area = edgeFunction(t.s[0], t.s[1], t.s[2]);
  if (area == 0) return false;
  precise vec3 n = cross(t.p[1] - t.p[0], t.p[2] - t.p[0]);
  precise float n_p0 = dot(n, t.p[0]);
  t.n = n;
  t.n_p0 = n_p0;
  t.zrange = vec2(min(t.p[0].z, min(t.p[1].z, t.p[2].z)), max(t.p[0].z, max(t.p[1].z, t.p[2].z)));
  t.sign = area > 0 ? 1 : -1;
  t.area = area * t.sign;
  int64_t x0 = min(t.s[0].x, min(t.s[1].x, t.s[2].x)), x1 = max(t.s[0].x, max(t.s[1].x, t.s[2].x));
  int64_t y0 = min(t.s[0].y, min(t.s[1].y, t.s[2].y)), y1 = max(t.s[0].y, max(t.s[1].y, t.s[2].y));
  // Pixel centres sit on integer coordinates (OpenCV's convention): x0 / 8 rounded up.
  t.box = ivec4(int(max(-floorDiv8(-x0), int64_t(0))), int(max(-floorDiv8(-y0), int64_t(0))),
                int(min(floorDiv8(x1), int64_t(pc.width - 1))), int(min(floorDiv8(y1), int64_t(pc.height - 1))));
  return t.box.x <= t.box.z && t.box.y <= t.box.w;
}

// Screen-space barycentric numerators at pixel (x, y); all >= 0 inside (edges included).
i64vec3 edgesAt(Triangle t, int x, int y) {
  i64vec2 p = i64vec2(int64_t(x) * 8, int64_t(y) * 8);
  return i64vec3(edgeFunction(t.s[1], t.s[2], p), edgeFunction(t.s[2], t.s[0], p), edgeFunction(t.s[0], t.s[1], p)) *
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
