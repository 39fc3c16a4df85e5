#pragma once
// LINEMOD templates as the matcher reads them: per pyramid level, a list of features
// (position relative to the template's top-left corner at that level, orientation bin,
// modality) and the template's size at that level.
#include <cstdint>
#include <vector>

#include "vkpose/features.hpp"

namespace vkpose {

struct TemplateFeature {
  int x = 0, y = 0;  ///< pixels at the template's level, relative to its top-left corner
  uint8_t bin = 0;   ///< orientation bin 0..7
  Modality modality = Modality::ColourGradient;
};

struct TemplateLevel {
  int width = 0, height = 0;  ///< pixels at this level
  std::vector<TemplateFeature> features;
};

/// One view of one object; levels finest first, as many as FeatureParams::T.
struct LinemodTemplate {
  std::vector<TemplateLevel> levels;
};

/// Cells (pixels / T) a template spans at a level, as LINEMOD counts them: (size - 1) / T + 1.
inline int templateCells(int size_px, int T) { return size_px <= 0 ? 1 : (size_px - 1) / T + 1; }

/// Throws InputError when a template has the wrong number of levels, no features, a negative
/// or out-of-range position, a bin outside 0..7, or a modality that FeatureParams switches off.
void validateTemplates(const std::vector<LinemodTemplate>& templates, const FeatureParams& params);

}  // namespace vkpose
