#pragma once
// Meshes built in code for the render and training tests: exact shapes whose depth can be
// computed by ray casting.
#include "vkpose/geometry.hpp"

namespace vkpose::test {

/// Axis-aligned box centred at `centre` with the given side lengths (metres).
Mesh boxMesh(const Eigen::Vector3f& size, const Eigen::Vector3f& centre = Eigen::Vector3f::Zero());
/// An icosphere of `radius` (metres), `subdivisions` times refined (20 * 4^n triangles).
Mesh icosphere(float radius, int subdivisions);
/// Two boxes forming an "L": no symmetry, so a mirrored or flipped rendering shows.
Mesh lShapeMesh();
/// Appends `b`'s triangles to `a`.
void appendMesh(Mesh& a, const Mesh& b);

}  // namespace vkpose::test
