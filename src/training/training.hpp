#pragma once
// Training internals: the tile a template is rendered into and the features of one rendering.
#include <vector>

#include <opencv2/core.hpp>

#include "render/render.hpp"
#include "vkpose/bank.hpp"

namespace vkpose {

/// The square tile training renders into: the params' focal length (made square), the
/// object's centre at the tile's centre, big enough for the object from the nearest view.
Camera trainingCamera(const Mesh& mesh, const TrainingParams& params, const std::vector<TrainingView>& views);

/// The features of one rendering (tile pixels) as a template; `ok` false when a modality
/// that is on has fewer than 4 features at some level.
struct ExtractedTemplate {
  bool ok = false;
  LinemodTemplate linemod;
  int origin_x = 0, origin_y = 0;  ///< template top-left in the rendering, level-0 pixels
  cv::Rect object;                 ///< the object's bounding box in the rendering
};
ExtractedTemplate extractTemplate(const Rendering& rendering, const TrainingParams& params);

// extractTemplate in its two steps, so that the first can run on the GPU for many views at
// once (view_features.hpp): quantize the crop around the object, then pick the features.

/// The part of a tile the features of an object with box `object` depend on: the box plus a
/// margin covering every filter's reach at every level, its origin a multiple of 2^levels.
cv::Rect featureCrop(const cv::Rect& object, cv::Size tile, std::size_t levels);

/// Metres (CV_32FC1) to the millimetres (CV_16UC1) the depth modality quantizes.
cv::Mat depthMillimetres(const cv::Mat& depth_m);

/// A crop's quantized features, per pyramid level (finest first): colour labels (CV_8UC1)
/// with the squared gradient magnitude they come from (CV_32SC1), and depth labels; empty
/// for a modality that is off.
struct QuantizedView {
  std::vector<cv::Mat> colour, magnitude, depth;
};

/// The CPU reference of the quantization (features.hpp) of one crop.
QuantizedView quantizeView(const Rendering& crop, const FeatureParams& params);

/// Where training quantizes its views: on the GPU, many crops at once (the default), or with
/// the CPU reference one by one (the parity test's twin).
enum class FeatureQuantization { gpu, cpu_reference };

/// trainTemplatesFromViews with the quantization chosen.
TemplateBank trainTemplatesWith(const GpuContext& ctx, const Mesh& mesh, const TrainingParams& params,
                                const std::vector<TrainingView>& views, FeatureQuantization quantization,
                                const TrainingProgress& progress = {}, TrainingTimings* timings = nullptr);

/// LINEMOD's feature choice on a quantized crop: `mask` is the object's mask over the crop,
/// `roi` the crop in the tile, `object` the object's box in the tile.
ExtractedTemplate selectFeatures(const QuantizedView& view, const cv::Mat& mask, const cv::Rect& roi,
                                 const cv::Rect& object, const TrainingParams& params);

}  // namespace vkpose
