#pragma once
// C++ twin of shaders/raster_common.glsl: the same fixed-point coverage and the same float
// operations in the same order, for the reference rasterizer.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>

#include "render/render.hpp"
#include "vkpose/geometry.hpp"

namespace vkpose::render {

constexpr float kSubpixel = 8.0f;
constexpr float kNearZ = 1e-3f;
constexpr float kGuardPx = 1048576.0f;

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

/// The shader's camera constants, as floats.
struct ScreenParams {
  float fx, fy, cx, cy;
  int width, height;
  explicit ScreenParams(const Camera& c)
      : fx(static_cast<float>(c.fx)), fy(static_cast<float>(c.fy)), cx(static_cast<float>(c.cx)),
        cy(static_cast<float>(c.cy)), width(c.width), height(c.height) {}
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

inline bool setupTriangle(const ScreenParams& sp, const Pose& pose, const std::array<Eigen::Vector3f, 3>& v,
                          Triangle& t) {
  for (int i = 0; i < 3; ++i) {
    t.p[i] = toCamera(pose, v[i]);
    if (!(t.p[i].z() > kNearZ)) return false;
    const float rz = 1.0f / t.p[i].z();
    const float sx = sp.fx * (t.p[i].x() * rz) + sp.cx;
    const float sy = sp.fy * (t.p[i].y() * rz) + sp.cy;
    if (!(std::abs(sx) < kGuardPx && std::abs(sy) < kGuardPx)) return false;
    t.rz[i] = rz;
    t.s[i] = {static_cast<int64_t>(std::floor(sx * kSubpixel + 0.5f)), static_cast<int64_t>(std::floor(sy * kSubpixel + 0.5f))};
  }
  const int64_t area = edgeFunction(t.s[0], t.s[1], t.s[2]);
  if (area == 0) return false;
  const Eigen::Vector3f e1 = t.p[1] - t.p[0], e2 = t.p[2] - t.p[0];
  // cross() and dot() spelled out in the shader's order of operations.
  t.n = {e1.y() * e2.z() - e2.y() * e1.z(), e1.z() * e2.x() - e2.z() * e1.x(), e1.x() * e2.y() - e2.x() * e1.y()};
  t.n_p0 = t.n.x() * t.p[0].x() + t.n.y() * t.p[0].y() + t.n.z() * t.p[0].z();
  t.z_near = std::min({t.p[0].z(), t.p[1].z(), t.p[2].z()});
  t.z_far = std::max({t.p[0].z(), t.p[1].z(), t.p[2].z()});
  t.sign = area > 0 ? 1 : -1;
  t.area = area * t.sign;
  const int64_t x0 = std::min({t.s[0].x, t.s[1].x, t.s[2].x}), x1 = std::max({t.s[0].x, t.s[1].x, t.s[2].x});
  const int64_t y0 = std::min({t.s[0].y, t.s[1].y, t.s[2].y}), y1 = std::max({t.s[0].y, t.s[1].y, t.s[2].y});
  t.box_x0 = static_cast<int>(std::max<int64_t>(-floorDiv8(-x0), 0));
  t.box_y0 = static_cast<int>(std::max<int64_t>(-floorDiv8(-y0), 0));
  t.box_x1 = static_cast<int>(std::min<int64_t>(floorDiv8(x1), sp.width - 1));
  t.box_y1 = static_cast<int>(std::min<int64_t>(floorDiv8(y1), sp.height - 1));
  return t.box_x0 <= t.box_x1 && t.box_y0 <= t.box_y1;
}

inline std::array<int64_t, 3> edgesAt(const Triangle& t, int x, int y) {
  const Fixed2 p{int64_t{x} * 8, int64_t{y} * 8};
  return {edgeFunction(t.s[1], t.s[2], p) * t.sign, edgeFunction(t.s[2], t.s[0], p) * t.sign,
          edgeFunction(t.s[0], t.s[1], p) * t.sign};
}

inline float depthAt(const ScreenParams& sp, const Triangle& t, int x, int y) {
  const float rx = (static_cast<float>(x) - sp.cx) * (1.0f / sp.fx), ry = (static_cast<float>(y) - sp.cy) * (1.0f / sp.fy);
  const float denom = t.n.x() * rx + t.n.y() * ry + t.n.z() * 1.0f;
  const float z = denom != 0.0f ? t.n_p0 * (1.0f / denom) : t.z_far;
  return std::clamp(z, t.z_near, t.z_far);
}

inline uint32_t packChannel(float c) { return static_cast<uint32_t>(std::clamp(c, 0.0f, 1.0f) * 255.0f + 0.5f); }

}  // namespace vkpose::render
