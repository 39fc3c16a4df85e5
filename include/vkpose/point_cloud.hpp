#pragma once
// A plain point cloud, the currency of the pose stages (DESIGN.md stages 6-8). No PCL or
// OctoMap type appears in a public header: those libraries stay inside src/pose/.
#include <vector>

#include <Eigen/Core>

namespace vkpose {

/// Points in metres; the frame (camera or object) is said where a cloud is used.
using PointCloud = std::vector<Eigen::Vector3f>;

}  // namespace vkpose
