#include "render/simplify.hpp"

#include <vector>

#include <meshoptimizer.h>

namespace vkpose {

Mesh simplifiedForRendering(const Mesh& mesh, float max_error_m) {
  if (mesh.faces.empty() || mesh.vertices.empty() || !(max_error_m > 0.f)) return mesh;
  std::vector<unsigned> indices;
  indices.reserve(mesh.faces.size() * 3);
  for (const auto& f : mesh.faces)
    for (int k = 0; k < 3; ++k) indices.push_back(static_cast<unsigned>(f[k]));
  static_assert(sizeof(Eigen::Vector3f) == 3 * sizeof(float));
  const float* positions = mesh.vertices.front().data();
  // meshoptimizer's error is relative to the mesh's extent.
  const float scale = meshopt_simplifyScale(positions, mesh.vertices.size(), sizeof(Eigen::Vector3f));
  if (!(scale > 0.f)) return mesh;
  std::vector<unsigned> kept(indices.size());
  const std::size_t n = meshopt_simplify(kept.data(), indices.data(), indices.size(), positions, mesh.vertices.size(),
                                         sizeof(Eigen::Vector3f), /*target_index_count=*/0, max_error_m / scale);
  if (n == 0 || n >= indices.size()) return mesh;
  Mesh out = mesh;
  out.faces.clear();
  out.faces.reserve(n / 3);
  for (std::size_t i = 0; i + 2 < n; i += 3)
    out.faces.emplace_back(static_cast<int>(kept[i]), static_cast<int>(kept[i + 1]), static_cast<int>(kept[i + 2]));
  return out;
}

}  // namespace vkpose
