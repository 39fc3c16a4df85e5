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

}  // namespace vkpose
