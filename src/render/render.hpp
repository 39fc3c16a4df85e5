#pragma once
// Rendering a mesh with compute shaders (docs/pipeline.md, stage 0: no OpenGL). Many views render
// per submit; each gives depth, normals, mask and colour. renderReference is the plain C++
// rasterizer the GPU kernels are tested against.
#include <memory>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <Eigen/LU>
#include <opencv2/core.hpp>

#include "vkpose/device.hpp"
#include "vkpose/geometry.hpp"

namespace vkpose {

/// One rendered view. Pixel centres sit at integer coordinates (x = fx X / Z + cx).
struct Rendering {
  cv::Mat depth;    ///< CV_32FC1: z in metres, 0 where the object is not
  cv::Mat normals;  ///< CV_32FC3: unit normals in the camera frame, facing the camera; 0 outside
  cv::Mat bgr;      ///< CV_8UC3: vertex colour, or grey shaded by a light at the camera
  cv::Mat mask() const { return depth > 0.f; }
};

/// The C++ reference rasterizer: the same fixed-point coverage, depth test and float
/// arithmetic as the GPU kernels (shaders/raster_*.comp).
Rendering renderReference(const Mesh& mesh, const Camera& camera, const Pose& pose);

/// The rendering a camera rotated by `degrees` about its optical axis would see: for square
/// pixels (fx = fy) that is the image rotated about the principal point (cx, cy), with
/// normals rotated alike. Nearest-neighbour resampling, so depth values stay exact.
Rendering rotateInPlane(const Rendering& r, float degrees, double cx, double cy);

/// Renders a mesh on the GPU. The mesh stays on the device; render() splits the views into
/// batches that fit the device's buffer limits, one submit per batch.
/// The command batch, staging memory and full-frame outputs MeshRenderer::render works in:
/// about 56 bytes per pixel and pose of a batch (up to about 170 MiB at 640x480). Renderers that
/// never render at the same time (the detector's, one per bank, render one after another)
/// share one, so N meshes hold it once rather than N times.
struct RenderWorkspace;
std::shared_ptr<RenderWorkspace> makeRenderWorkspace(const GpuContext& ctx);

/// What MeshRenderer::render fills in each Rendering.
enum class RenderedImages { all, depth };

class MeshRenderer {
 public:
  /// Without `workspace` the renderer has one of its own; with it, the caller promises that
  /// the renderers sharing it never render concurrently.
  MeshRenderer(const GpuContext& ctx, const Mesh& mesh, std::shared_ptr<RenderWorkspace> workspace = {});
  ~MeshRenderer();
  MeshRenderer(const MeshRenderer&) = delete;
  MeshRenderer& operator=(const MeshRenderer&) = delete;

  /// `images`: RenderedImages::depth leaves each rendering's normals and colours empty, and
  /// costs the resolve pass nearly nothing (its depth is pass 1's).
  std::vector<Rendering> render(const Camera& camera, const std::vector<Pose>& poses,
                                RenderedImages images = RenderedImages::all);
  /// Pose i as cameras[i] sees it (its size and principal point; every camera of the call of
  /// one focal length, as the windows of one frame are): one submit for a batch of views
  /// where a render() each costs a submit each, the same pixels.
  std::vector<Rendering> render(const std::vector<Camera>& cameras, const std::vector<Pose>& poses,
                                RenderedImages images = RenderedImages::all);
  /// Views that render per submit at this image size.
  std::size_t viewsPerBatch(const Camera& camera) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace vkpose
