#pragma once
// Synthetic RGB-D scenes: several meshes at known poses rendered with the training renderer
// into one frame (nearest surface wins), and the depth noise of a structured-light sensor.
// Tests and benchmarks use them where a ground truth is needed that real frames lack.
#include <cstdint>
#include <vector>

#include "vkpose/features.hpp"
#include "vkpose/render.hpp"

namespace vkpose {

struct SceneObject {
  const Mesh* mesh = nullptr;
  Pose pose;
};

struct SceneRendering {
  cv::Mat depth;     ///< CV_32FC1 metres, 0 where nothing is
  cv::Mat bgr;       ///< CV_8UC3
  cv::Mat instance;  ///< CV_16UC1: 1 + index of the object seen at each pixel, 0 for none
  /// Pixels of each object that are visible, and that it would cover alone.
  std::vector<int> visible_pixels, full_pixels;
  float visibleFraction(std::size_t i) const {
    return full_pixels[i] > 0 ? static_cast<float>(visible_pixels[i]) / static_cast<float>(full_pixels[i]) : 0.f;
  }
};

/// Renders every object (one GPU renderer per distinct mesh) and keeps the nearest surface.
SceneRendering renderScene(const GpuContext& ctx, const std::vector<SceneObject>& objects, const Camera& camera);

/// A flat square of side `size` metres in the object's x-y plane, centred at its origin,
/// `grey` 0..1: a table under or behind the objects.
Mesh planeMesh(float size, float grey = 0.55f);

/// Structured-light depth noise: axial Gaussian noise growing with distance squared,
/// quantization, and dropouts at depth edges.
struct DepthNoiseParams {
  float axial_sigma_at_1m = 0.0015f;  ///< metres at 1 m; sigma(z) = this * z^2 (Kinect-like)
  float quantization_m = 0.001f;      ///< the sensor's depth step (16-bit PNG in mm)
  float edge_jump_m = 0.02f;          ///< a neighbour this much nearer or farther marks an edge
  float edge_dropout = 0.5f;          ///< chance that an edge pixel reads nothing
  float colour_sigma = 3.f;           ///< Gaussian noise on each colour channel, grey levels
};

/// The frame a sensor would deliver (depth in millimetres, 0 = no reading); reproducible
/// from `seed`.
LinemodFrame sensorFrame(const SceneRendering& scene, const DepthNoiseParams& noise, uint32_t seed);

}  // namespace vkpose
