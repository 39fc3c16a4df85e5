// Pose verification with OctoMap (DESIGN.md stage 8): the collision rate of the posed model's
// visible points against an octree of the scene points.
#include "vkpose/verify.hpp"

#include <chrono>
#include <cmath>

#include <Eigen/Geometry>
#include <fmt/core.h>
#include <octomap/OcTree.h>

#include "vkpose/error.hpp"

namespace vkpose {

void validateVerifyParams(const VerifyParams& params) {
  if (!(params.resolution > 0.f) || !std::isfinite(params.resolution))
    throw InputError(fmt::format("octree resolution must be positive and finite, got {}", params.resolution));
  if (!(params.crop_margin >= 0.f) || !std::isfinite(params.crop_margin))
    throw InputError(fmt::format("verification crop margin must be >= 0 and finite, got {}", params.crop_margin));
  if (!std::isfinite(params.threshold))
    throw InputError(fmt::format("collision rate threshold must be finite, got {}", params.threshold));
}

VerifyResult verifyPose(const PointCloud& visible_model_points, const PointCloud& scene_points,
                        const VerifyParams& params) {
  validateVerifyParams(params);

  const auto t0 = std::chrono::steady_clock::now();
  VerifyResult result;
  Eigen::AlignedBox3f box;  // the model's box: only scene points near it can be hit
  for (const auto& p : visible_model_points)
    if (p.allFinite()) {
      box.extend(p);
      ++result.model_points;
    }

  if (result.model_points > 0) {
    box.min().array() -= params.crop_margin;
    box.max().array() += params.crop_margin;
    // One update per occupied leaf rather than per point: a dense crop puts tens of points
    // in each 4 mm leaf, and the octree descent is the cost.
    octomap::OcTree tree(params.resolution);
    octomap::KeySet occupied;
    octomap::OcTreeKey key;
    for (const auto& p : scene_points)
      if (p.allFinite() && box.contains(p)) {
        ++result.scene_points;
        if (tree.coordToKeyChecked(p.x(), p.y(), p.z(), key)) occupied.insert(key);
      }
    for (const auto& k : occupied) tree.updateNode(k, true, /*lazy_eval=*/true);  // leaves only

    for (const auto& p : visible_model_points) {
      if (!p.allFinite() || !tree.coordToKeyChecked(p.x(), p.y(), p.z(), key)) continue;
      const octomap::OcTreeNode* node = tree.search(key);
      if (node && tree.isNodeOccupied(node)) ++result.hits;
    }
    result.collision_rate = float(double(result.hits) / double(result.model_points));
  }
  result.accepted = result.model_points > 0 && result.collision_rate > params.threshold;
  result.ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  return result;
}

}  // namespace vkpose
