#pragma once
// Synthetic RGB-D scenes: several meshes at known poses rendered with the training renderer
// into one frame (nearest surface wins), and the depth noise of a structured-light sensor.
// Tests and benchmarks use them where a ground truth is needed that real frames lack.
#include <cstdint>
#include <vector>

#include "match/features.hpp"
#include "render/render.hpp"
#include "vkpose/synth.hpp"

namespace vkpose {

struct SceneObject {
  const Mesh* mesh = nullptr;
  Pose pose;
};

struct SceneRendering {
  Camera camera;     ///< the camera it was rendered with
  cv::Mat depth;     ///< CV_32FC1 metres, 0 where nothing is
  cv::Mat normals;   ///< CV_32FC3 unit normals in the camera frame, facing the camera; 0 where nothing is
  cv::Mat bgr;       ///< CV_8UC3
  cv::Mat instance;  ///< CV_16UC1: 1 + index of the object seen at each pixel, 0 for none
  /// Pixels of each object that are visible, and that it would cover alone (the part the
  /// image border cuts off included, as BOP counts px_count_all).
  std::vector<int> visible_pixels, full_pixels;
  /// CV_8UC1 silhouette of each object alone (255 inside): what it would cover unoccluded.
  std::vector<cv::Mat> full_masks;
  /// CV_8UC1, 255 where the surface seen is bare metal (markMetal); empty: nothing is.
  cv::Mat metal;
  float visibleFraction(std::size_t i) const {
    return full_pixels[i] > 0 ? static_cast<float>(visible_pixels[i]) / static_cast<float>(full_pixels[i]) : 0.f;
  }
};

/// Renders every object (one GPU renderer per distinct mesh) and keeps the nearest surface.
SceneRendering renderScene(const GpuContext& ctx, const std::vector<SceneObject>& objects, const Camera& camera);

/// A flat square of side `size` metres in the object's x-y plane, centred at its origin,
/// `grey` 0..1: a table under or behind the objects.
Mesh planeMesh(float size, float grey = 0.55f);

/// A box of side lengths `size` (metres) centred at the origin, flat-shaded (its own vertices
/// per face), of one colour (RGB 0..1): clutter, bin walls. With `max_tile_m` > 0 each face is
/// made of tiles no larger than that, as planeMesh's are: the rasterizer once dropped a
/// triangle with a corner behind the camera (a bin seen from close by reaches behind it); it
/// clips them now, and the tiles stay so that synth's datasets keep their bytes.
Mesh cuboidMesh(const Eigen::Vector3f& size, const Eigen::Vector3f& rgb, float max_tile_m = 0.f);

/// A closed cylinder along z centred at the origin, `segments` sides: cans and jars as clutter.
Mesh cylinderMesh(float radius, float height, const Eigen::Vector3f& rgb, int segments = 32);

/// Light on a scene whose colours are albedos (meshes with vertex colours render unshaded):
/// a directional light with ambient and a specular highlight, and a per-channel gain for
/// exposure and white balance, so that the same object looks different from frame to frame.
struct Lighting {
  Eigen::Vector3f direction = {0.f, 0.f, 1.f};  ///< camera frame, from the light into the scene
  float ambient = 0.35f;                        ///< share of the albedo lit from everywhere
  float diffuse = 0.65f;                        ///< Lambert term's weight
  float specular = 0.f;                         ///< Phong highlight's weight, grey levels / 255
  float shininess = 20.f;                       ///< Phong exponent
  Eigen::Vector3f gain = Eigen::Vector3f::Ones();  ///< per channel (B, G, R)
};

/// Replaces scene.bgr (albedo) by albedo * gain * (ambient + diffuse * n.l) + highlight, using
/// scene.normals; pixels where nothing is stay as they are. Where scene.metal is set,
/// metalLighting(light) instead.
void applyLighting(SceneRendering& scene, const Lighting& light);

/// Bare metal under `light`: a grey that the diffuse light barely brightens, sharp highlights
/// of the light, and a lamp beside the lens (a ring light, or the projector's own flash) that
/// lights whatever faces the camera: the bright stripe along a tube, the flat of a nut.
struct MetalLighting {
  Lighting light;
  float headlight = 0.9f;          ///< the lamp's highlight weight, grey levels / 255
  float headlight_shininess = 12.f;
};
MetalLighting metalLighting(const Lighting& light);

/// Marks objects [first, last) of the scene as bare metal in scene.metal.
void markMetal(SceneRendering& scene, std::size_t first, std::size_t last);

/// The scene's depth as a camera with a `window`-pixel correlation window measures it: each
/// pixel the median of the surface depths within the window (holes ignored; none where most of
/// the window is empty). Only pixels near a depth change differ from the input: the median of
/// a plane's window is its centre.
cv::Mat windowMedianDepth(const cv::Mat& depth, int window);

/// The frame as a monochrome camera gives it: each pixel's luminance in all three channels.
void toGreyscale(LinemodFrame& frame);

/// The frame a sensor would deliver (depth in millimetres, 0 = no reading); reproducible
/// from `seed`. Grazing dropouts use scene.normals and scene.camera.
LinemodFrame sensorFrame(const SceneRendering& scene, const DepthNoiseParams& noise, uint32_t seed);

}  // namespace vkpose
