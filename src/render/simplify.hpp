#pragma once
// A coarser copy of a mesh for the detector's renderings (stage 6 and the checks after ICP).
// Scanned and CAD meshes often carry a triangle per millimetre: at 0.6-1 m a pixel covers
// 1-2 mm of the object, so most triangles cover a pixel or less and the rasterizer's cost is
// their setup (docs/performance.md). meshoptimizer stays inside src/render/simplify.cpp.
#include "vkpose/geometry.hpp"

namespace vkpose {

/// How far the detector's renderings may move the surface, share of the diameter: 0.27 mm on
/// the 13.7 cm cup, under half a pixel at 0.6 m even with the 1.7 below.
constexpr float kDetectionRenderError = 0.002f;

/// Edge collapses (meshoptimizer's quadric simplifier) while the surface moves by about
/// `max_error_m` at most: the bound is meshoptimizer's quadric estimate, which on a sphere
/// undershoots (the surface moved up to 1.7 times it; tests/render/render_test.cpp). Vertices keep
/// their positions, normals and colours (only faces go), and vertices that share a position
/// but differ in colour or normal are a seam the simplifier keeps, so painted faces keep their
/// borders. Returns the mesh unchanged when nothing can go.
Mesh simplifiedForRendering(const Mesh& mesh, float max_error_m);

}  // namespace vkpose
