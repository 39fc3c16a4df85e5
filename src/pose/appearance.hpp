#pragma once
// Render and compare (docs/pipeline.md, stage 8, near-symmetries): a pose's rendering against
// the scene's colour and depth. A pose and its near-symmetric alternatives (symmetry.hpp)
// fit the scene's depth about equally; where the mesh is coloured, its colours tell them apart.
#include <opencv2/core.hpp>

#include "render/render.hpp"

namespace vkpose {

struct AppearanceAgreement {
  int pixels = 0;          ///< rendered pixels with scene depth that nothing in front hides
  float depth_fit = 0.f;   ///< share of them within the tolerance of the scene's depth
  /// Correlation (-1..1) of the rendered and the scene's chromaticity (r, g of r+g+b: blind to
  /// shading and brightness) over the fitting pixels that are bright enough to have one.
  float colour = 0.f;
  /// The rendering has colour that varies (a painted mesh): colour counts. False for an
  /// uncoloured mesh (grey shading) or a single-coloured one.
  bool colour_informative = false;
  /// depth_fit * (1 + colour) / 2 where colour counts, else depth_fit.
  float score = 0.f;
};

/// `rendering` covers `window` of the scene (MeshRenderer::render through windowCamera).
/// scene_bgr: CV_8UC3, scene_depth_m: CV_32FC1 (0 = none), both full frames of one size.
AppearanceAgreement appearanceAgreement(const Rendering& rendering, const cv::Rect& window, const cv::Mat& scene_bgr,
                                        const cv::Mat& scene_depth_m, float depth_tolerance);

}  // namespace vkpose
