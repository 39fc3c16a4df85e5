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
  /// Mean |scene - rendered| depth over them, each capped at the tolerance (metres): the
  /// whole mask's residual, which tells a pose from a look-alike turn a centimetre off where
  /// both fit within the tolerance.
  float depth_residual_m = 0.f;
  /// Concordance (-1..1) of the rendered and the scene's chromaticity (r, g of r+g+b: blind to
  /// shading and brightness) over the fitting pixels that are bright enough to have one:
  /// 2 cov / (var_rendered + var_seen + w |mean difference|^2), w = 1 where the rendering is of
  /// about one colour and fading as its colours vary (then it is about a correlation). Unlike a
  /// correlation it is defined where the rendering shows one colour (one painted face of a box
  /// lying down): 1 when the seen face has that colour, near 0 when another, so every
  /// alternative of a pose is scored on one scale.
  float colour = 0.f;
  /// Colour counted (the caller said the mesh has colours that vary, and enough pixels had one).
  bool colour_informative = false;
  /// depth_fit * (1 + colour) / 2 where colour counts, else depth_fit.
  float score = 0.f;
};

/// Below this spread (standard deviation of (r, g) chromaticity) colours do not tell places
/// apart: an uncoloured mesh renders grey, a single-coloured one is its own look-alike.
constexpr double kMinChromaSpread = 0.05;

/// The spread of a mesh's vertex colours' chromaticity (0 without colours): the detector lets
/// colour count for meshes of at least kMinChromaSpread.
double meshChromaSpread(const Mesh& mesh);

/// The spread (as kMinChromaSpread's) of the scene's chromaticity over the rendering's mask,
/// 2 px in from its outline (a pose a pixel off would count its surroundings); NaN where fewer
/// than 20 pixels are bright enough to have one. Under kMinChromaSpread the pose lies on a
/// surface of one colour. `rendering` covers `window` of `scene_bgr` (CV_8UC3).
double seenChromaSpread(const Rendering& rendering, const cv::Rect& window, const cv::Mat& scene_bgr);

/// How well the scene's colours tell the rendering's mask from its surroundings: of the pixels
/// 2 px and more inside the mask and of those 2 to `band_px` px outside it,
/// the share that colour histograms of the two (8 levels a channel) assign to their own side,
/// both shares added less 1 (0: the same colours on both sides, 1: told apart everywhere; the
/// histograms are of the pixels they judge, so a few dozen pixels of noise already score above
/// 0). A pose on its object separates the object from what lies around it; a pose tilted or
/// scaled off it, or laid inside a larger object, takes in some of its surroundings or leaves
/// some of the object outside. 0 where either side has fewer than 20 pixels in the scene.
float regionContrast(const Rendering& rendering, const cv::Rect& window, const cv::Mat& scene_bgr, int band_px = 12);

/// `rendering` covers `window` of the scene (MeshRenderer::render through windowCamera).
/// scene_bgr: CV_8UC3, scene_depth_m: CV_32FC1 (0 = none), both full frames of one size.
/// Without `colour_counts` the score is the depth fit alone.
AppearanceAgreement appearanceAgreement(const Rendering& rendering, const cv::Rect& window, const cv::Mat& scene_bgr,
                                        const cv::Mat& scene_depth_m, float depth_tolerance, bool colour_counts);

}  // namespace vkpose
