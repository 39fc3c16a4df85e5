#pragma once
// A plain point cloud, the currency of the pose stages (docs/pipeline.md, stages 6-8). No PCL or
// OctoMap type appears in a public header: those libraries stay inside src/pose/.
#include <vector>

#include <Eigen/Core>

#include "vkpose/geometry.hpp"

namespace vkpose {

/// Points in metres; the frame (camera or object) is said where a cloud is used.
using PointCloud = std::vector<Eigen::Vector3f>;

/// R p + t for every point: a cloud moved by a pose (e.g. object frame to camera frame).
inline PointCloud transformed(const PointCloud& points, const Pose& pose) {
  PointCloud out;
  out.reserve(points.size());
  for (const auto& p : points) out.push_back(pose.R * p + pose.t);
  return out;
}

}  // namespace vkpose
