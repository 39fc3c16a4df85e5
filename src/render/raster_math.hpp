#pragma once
// C++ twin of shaders/raster_common.glsl: the same fixed-point coverage and the same float
// operations in the same order, for the reference rasterizer.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>

#include "gpu/kernel_interface.h"
#include "render/render.hpp"
#include "vkpose/geometry.hpp"

namespace vkpose::render {

// The kernels' own constants (fixed point, near and clip planes, guard band).
using gpu::kClipZ;
using gpu::kGuardPx;
using gpu::kNearZ;
using gpu::kSubpixel;

struct Fixed2 {
  int64_t x = 0, y = 0;
};

struct Triangle {
  std::array<Eigen::Vector3f, 3> p;
  std::array<Fixed2, 3> s;
  int64_t area = 0, sign = 1;
  int box_x0 = 0, box_y0 = 0, box_x1 = -1, box_y1 = -1;
  std::array<float, 3> rz{};
  Eigen::Vector3f n = Eigen::Vector3f::Zero();
  float n_p0 = 0.f;
  float z_near = 0.f, z_far = 0.f;
};

/// The shader's camera constants (gpu::RasterPush): float intrinsics, whose ray() is the
/// raster kernels' viewing ray, and the image size.
struct ScreenParams : FloatIntrinsics {
  int width, height;
  explicit ScreenParams(const Camera& c) : FloatIntrinsics(c.floatIntrinsics()), width(c.width), height(c.height) {}
};

inline Eigen::Vector3f toCamera(const Pose& pose, const Eigen::Vector3f& v) {
  const auto& R = pose.R;
  return {R(0, 0) * v.x() + R(0, 1) * v.y() + R(0, 2) * v.z() + pose.t.x(),
          R(1, 0) * v.x() + R(1, 1) * v.y() + R(1, 2) * v.z() + pose.t.y(),
          R(2, 0) * v.x() + R(2, 1) * v.y() + R(2, 2) * v.z() + pose.t.z()};
}

inline int64_t floorDiv8(int64_t a) { return a >= 0 ? a / 8 : -((-a + 7) / 8); }

inline int64_t edgeFunction(Fixed2 a, Fixed2 b, Fixed2 p) {
  return (b.x - a.x) * (p.y - a.y) - (b.y - a.y) * (p.x - a.x);
}

/// cross() and dot() spelled out in the shader's order of operations.
inline Eigen::Vector3f crossAsShader(const Eigen::Vector3f& a, const Eigen::Vector3f& b) {
  return {a.y() * b.z() - b.y() * a.z(), a.z() * b.x() - b.z() * a.x(), a.x() * b.y() - b.x() * a.y()};
}
inline float dotAsShader(const Eigen::Vector3f& a, const Eigen::Vector3f& b) {
  return a.x() * b.x() + a.y() * b.y() + a.z() * b.z();
}

/// The shader's projectPoint: a camera point's 1 / z and fixed-point screen position; false
/// beyond the guard band.
inline bool projectPoint(const ScreenParams& sp, const Eigen::Vector3f& p, float& rz, Fixed2& s) {
  rz = 1.0f / p.z();
  const float sx = sp.fx * (p.x() * rz) + sp.cx;
  const float sy = sp.fy * (p.y() * rz) + sp.cy;
  s = {static_cast<int64_t>(std::floor(sx * kSubpixel + 0.5f)), static_cast<int64_t>(std::floor(sy * kSubpixel + 0.5f))};
  return std::abs(sx) < kGuardPx && std::abs(sy) < kGuardPx;
}

/// The shader's pixelBox: inclusive pixel bounds of fixed-point corners from (x0, y0) to
/// (x1, y1), clipped to the image; false when nothing is left.
inline bool pixelBox(const ScreenParams& sp, int64_t x0, int64_t y0, int64_t x1, int64_t y1, int& box_x0,
                     int& box_y0, int& box_x1, int& box_y1) {
  box_x0 = static_cast<int>(std::max<int64_t>(-floorDiv8(-x0), 0));
  box_y0 = static_cast<int>(std::max<int64_t>(-floorDiv8(-y0), 0));
  box_x1 = static_cast<int>(std::min<int64_t>(floorDiv8(x1), sp.width - 1));
  box_y1 = static_cast<int>(std::min<int64_t>(floorDiv8(y1), sp.height - 1));
  return box_x0 <= box_x1 && box_y0 <= box_y1;
}

inline bool setupTriangle(const ScreenParams& sp, const Pose& pose, const std::array<Eigen::Vector3f, 3>& v,
                          Triangle& t) {
  for (int i = 0; i < 3; ++i) {
    t.p[i] = toCamera(pose, v[i]);
    if (!(t.p[i].z() > kNearZ)) return false;
    if (!projectPoint(sp, t.p[i], t.rz[i], t.s[i])) return false;
  }
  const int64_t area = edgeFunction(t.s[0], t.s[1], t.s[2]);
  if (area == 0) return false;
  t.n = crossAsShader(t.p[1] - t.p[0], t.p[2] - t.p[0]);
  t.n_p0 = dotAsShader(t.n, t.p[0]);
  t.z_near = std::min({t.p[0].z(), t.p[1].z(), t.p[2].z()});
  t.z_far = std::max({t.p[0].z(), t.p[1].z(), t.p[2].z()});
  t.sign = area > 0 ? 1 : -1;
  t.area = area * t.sign;
  const int64_t x0 = std::min({t.s[0].x, t.s[1].x, t.s[2].x}), x1 = std::max({t.s[0].x, t.s[1].x, t.s[2].x});
  const int64_t y0 = std::min({t.s[0].y, t.s[1].y, t.s[2].y}), y1 = std::max({t.s[0].y, t.s[1].y, t.s[2].y});
  return pixelBox(sp, x0, y0, x1, y1, t.box_x0, t.box_y0, t.box_x1, t.box_y1);
}

inline std::array<int64_t, 3> edgesAt(const Triangle& t, int x, int y) {
  const Fixed2 p{int64_t{x} * 8, int64_t{y} * 8};
  return {edgeFunction(t.s[1], t.s[2], p) * t.sign, edgeFunction(t.s[2], t.s[0], p) * t.sign,
          edgeFunction(t.s[0], t.s[1], p) * t.sign};
}

inline float planeDepthAt(const ScreenParams& sp, const Eigen::Vector3f& n, float n_p0, float z_near, float z_far,
                          int x, int y) {
  const Eigen::Vector3f r = sp.ray(x, y);
  const float denom = n.x() * r.x() + n.y() * r.y() + n.z() * 1.0f;
  const float z = denom != 0.0f ? n_p0 * (1.0f / denom) : z_far;
  return std::clamp(z, z_near, z_far);
}

inline float depthAt(const ScreenParams& sp, const Triangle& t, int x, int y) {
  return planeDepthAt(sp, t.n, t.n_p0, t.z_near, t.z_far, x, y);
}

/// The shader's ClippedFace: a face with a corner at kNearZ or nearer, cut at kClipZ.
struct ClippedFace {
  std::array<Fixed2, 4> s;
  int count = 0;
  int64_t sign = 1;
  int box_x0 = 0, box_y0 = 0, box_x1 = -1, box_y1 = -1;
  Eigen::Vector3f n = Eigen::Vector3f::Zero();
  float n_p0 = 0.f;
  float z_near = kClipZ, z_far = kClipZ;
};

/// False when no corner lies at kNearZ or nearer (setupTriangle's case), when nothing is left
/// in front of kClipZ, or when a corner of what is left falls beyond the guard band.
inline bool clipFace(const ScreenParams& sp, const Pose& pose, const std::array<Eigen::Vector3f, 3>& v,
                     ClippedFace& c) {
  std::array<Eigen::Vector3f, 3> p;
  for (int i = 0; i < 3; ++i) p[i] = toCamera(pose, v[i]);
  if (!(p[0].z() <= kNearZ || p[1].z() <= kNearZ || p[2].z() <= kNearZ)) return false;
  c.n = crossAsShader(p[1] - p[0], p[2] - p[0]);
  c.n_p0 = dotAsShader(c.n, p[0]);
  std::array<Eigen::Vector3f, 4> q;
  int m = 0;
  for (int i = 0; i < 3; ++i) {
    const Eigen::Vector3f& a = p[i];
    const Eigen::Vector3f& b = p[i == 2 ? 0 : i + 1];
    if (a.z() > kClipZ) q[m++] = a;
    if ((a.z() > kClipZ) != (b.z() > kClipZ)) {
      const float k = (kClipZ - a.z()) / (b.z() - a.z());
      const Eigen::Vector3f r = a + (b - a) * k;
      q[m++] = {r.x(), r.y(), kClipZ};
    }
  }
  if (m < 3) return false;
  c.count = m;
  c.z_near = c.z_far = kClipZ;
  int64_t x0 = INT64_MAX, y0 = INT64_MAX, x1 = INT64_MIN, y1 = INT64_MIN;
  for (int i = 0; i < m; ++i) {
    float rz;
    if (!projectPoint(sp, q[i], rz, c.s[i])) return false;
    x0 = std::min(x0, c.s[i].x), x1 = std::max(x1, c.s[i].x);
    y0 = std::min(y0, c.s[i].y), y1 = std::max(y1, c.s[i].y);
    c.z_far = std::max(c.z_far, q[i].z());
  }
  int64_t area = 0;  // twice the signed area: the winding
  for (int i = 0; i < m; ++i) {
    const Fixed2 a = c.s[i], b = c.s[i + 1 == m ? 0 : i + 1];
    area += a.x * b.y - b.x * a.y;
  }
  if (area == 0) return false;
  c.sign = area > 0 ? 1 : -1;
  return pixelBox(sp, x0, y0, x1, y1, c.box_x0, c.box_y0, c.box_x1, c.box_y1);
}

inline bool insideClipped(const ClippedFace& c, int x, int y) {
  const Fixed2 p{int64_t{x} * 8, int64_t{y} * 8};
  for (int i = 0; i < c.count; ++i)
    if (edgeFunction(c.s[i], c.s[i + 1 == c.count ? 0 : i + 1], p) * c.sign < 0) return false;
  return true;
}

/// Perspective-correct weights of the face's corners at the camera point `point` on its
/// plane, and the face's normal (unnormalized): for clipped faces.
inline Eigen::Vector3f faceWeights(const Pose& pose, const std::array<Eigen::Vector3f, 3>& v,
                                   const Eigen::Vector3f& point, Eigen::Vector3f& n) {
  const Eigen::Vector3f p0 = toCamera(pose, v[0]), p1 = toCamera(pose, v[1]), p2 = toCamera(pose, v[2]);
  n = crossAsShader(p1 - p0, p2 - p0);
  const float inv = 1.0f / dotAsShader(n, n);
  const float w0 = dotAsShader(crossAsShader(p1 - point, p2 - point), n) * inv;
  const float w1 = dotAsShader(crossAsShader(p2 - point, p0 - point), n) * inv;
  return {w0, w1, 1.0f - w0 - w1};
}

inline uint32_t packChannel(float c) { return static_cast<uint32_t>(std::clamp(c, 0.0f, 1.0f) * 255.0f + 0.5f); }

}  // namespace vkpose::render
