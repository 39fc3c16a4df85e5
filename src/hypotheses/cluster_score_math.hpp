#pragma once
// The per-member arithmetic of the cluster score, shared by the CPU reference and the GPU
// packing; shaders/cluster_score.comp is its GLSL twin (same order of operations).
#include <algorithm>
#include <cmath>

#include <Eigen/Core>

#include "hypotheses/cluster_score.hpp"

namespace vkpose::score {

/// Where a member's crop lands in the scene: cell (i, j) is scene pixel
/// (x0 + j * stride, y0 + i * stride).
struct MemberPlacement {
  int x0 = 0, y0 = 0;
};
inline MemberPlacement placeMember(const Hypothesis& h, const BankTemplate& t) {
  return {static_cast<int>(std::lround(h.x - t.anchor_x)) + t.crop.x0,
          static_cast<int>(std::lround(h.y - t.anchor_y)) + t.crop.y0};
}

/// Members scored of a hypothesis: the first max_members (0: all).
inline std::size_t scoredMembers(const Hypothesis& h, const ScoreParams& p) {
  return p.max_members > 0 ? std::min<std::size_t>(h.members.size(), static_cast<std::size_t>(p.max_members))
                           : h.members.size();
}

/// Scene depth at (x, y) in metres, 0 outside the image or without depth.
inline float sceneDepth(const cv::Mat& depth_m, int x, int y) {
  if (x < 0 || y < 0 || x >= depth_m.cols || y >= depth_m.rows) return 0.f;
  return depth_m.at<float>(y, x);
}

/// The scene normal at (x, y): the cross product of the back-projected depth differences
/// `step` pixels either side, turned towards the camera. False at depth edges, holes and the
/// image border.
/// The camera-frame point at pixel (u, v) with depth d, in the float arithmetic of the cluster
/// score kernel (cluster_score.comp): float intrinsics, the reciprocal of the float focal
/// length taken in float as the kernel does (the reciprocal of the double one, rounded, is
/// another float for about a quarter of focal lengths, the LINEMOD Kinect's among them).
inline Eigen::Vector3f backProject(const ScoreScene& s, int u, int v, float d) {
  const Eigen::Vector3f r = s.camera.floatIntrinsics().ray(u, v);
  return {r.x() * d, r.y() * d, d};
}

inline bool sceneNormal(const ScoreScene& s, int x, int y, int step, float max_jump, Eigen::Vector3f& n) {
  const float z = sceneDepth(s.depth_m, x, y);
  const float zl = sceneDepth(s.depth_m, x - step, y), zr = sceneDepth(s.depth_m, x + step, y);
  const float zu = sceneDepth(s.depth_m, x, y - step), zd = sceneDepth(s.depth_m, x, y + step);
  if (z <= 0.f || zl <= 0.f || zr <= 0.f || zu <= 0.f || zd <= 0.f) return false;
  if (std::abs(zl - z) > max_jump || std::abs(zr - z) > max_jump || std::abs(zu - z) > max_jump ||
      std::abs(zd - z) > max_jump)
    return false;
  auto point = [&](int u, int v, float d) { return backProject(s, u, v, d); };
  const Eigen::Vector3f dx = point(x + step, y, zr) - point(x - step, y, zl);
  const Eigen::Vector3f dy = point(x, y + step, zd) - point(x, y - step, zu);
  Eigen::Vector3f c = dx.cross(dy);
  const float len = c.norm();
  if (!(len > 0.f)) return false;
  c /= len;
  if (c.dot(point(x, y, z)) > 0.f) c = -c;
  n = c;
  return true;
}

/// One member's comparison: two passes over the crop (mean offset, then errors).
inline MemberScore scoreMember(const BankTemplate& t, const MemberPlacement& at, const Eigen::Matrix3f& ray_rotation,
                               const ScoreScene& scene, const ScoreParams& p) {
  const TemplateCrop& c = t.crop;
  MemberScore r;
  float offset_sum = 0.f;  // float sums, as the GLSL twin
  for (int i = 0; i < c.rows; ++i)
    for (int j = 0; j < c.cols; ++j) {
      const uint16_t dt = c.depth_01mm[static_cast<std::size_t>(i * c.cols + j)];
      if (dt == 0) continue;
      ++r.object_cells;
      const float ds = sceneDepth(scene.depth_m, at.x0 + j * c.stride, at.y0 + i * c.stride);
      if (ds <= 0.f) continue;
      ++r.depth_pairs;
      offset_sum += ds - static_cast<float>(dt) * 1e-4f;
    }
  if (r.depth_pairs == 0) return r;
  r.depth_offset = offset_sum / static_cast<float>(r.depth_pairs);
  float error_sum = 0.f, angle_sum = 0.f;
  for (int i = 0; i < c.rows; ++i)
    for (int j = 0; j < c.cols; ++j) {
      const std::size_t k = static_cast<std::size_t>(i * c.cols + j);
      const uint16_t dt = c.depth_01mm[k];
      if (dt == 0) continue;
      const int x = at.x0 + j * c.stride, y = at.y0 + i * c.stride;
      const float ds = sceneDepth(scene.depth_m, x, y);
      if (ds <= 0.f) continue;
      error_sum += std::min(std::abs(ds - static_cast<float>(dt) * 1e-4f - r.depth_offset), p.depth_cap_m);
      Eigen::Vector3f ns;
      if (!sceneNormal(scene, x, y, p.normal_step_px, p.normal_max_jump_m, ns)) continue;
      const Eigen::Vector3f nt =
          (ray_rotation * Eigen::Vector3f(c.normals[3 * k], c.normals[3 * k + 1], c.normals[3 * k + 2])).normalized();
      angle_sum += std::acos(std::clamp(nt.dot(ns), -1.f, 1.f));
      ++r.normal_pairs;
    }
  r.depth_error = error_sum / static_cast<float>(r.depth_pairs);
  r.angle_error = r.normal_pairs > 0 ? angle_sum / static_cast<float>(r.normal_pairs) : 0.f;
  return r;
}

}  // namespace vkpose::score
