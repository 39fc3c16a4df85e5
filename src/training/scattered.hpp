// LINEMOD's scattered feature selection: of a view's candidate features, the best ones spread
// over the object (cv::linemod's selectScatteredFeatures, made exact and fast).
#pragma once

#include <cstdint>
#include <vector>

namespace vkpose {

/// A feature a view could keep: its pixel, its quantized label's bit, and how good it is
/// (gradient magnitude, or distance to the nearest change of surface normal). Not negative.
struct FeatureCandidate {
  int x = 0, y = 0;
  uint8_t bin = 0;
  float score = 0.f;
};

/// Up to `count` candidates: best first (ties in their given order), each at least `distance`
/// pixels from those already taken, the distance starting at size / count + 1 and relaxing by
/// one pixel after every pass over them; the same choice as that plain loop.
std::vector<FeatureCandidate> selectScattered(std::vector<FeatureCandidate> candidates, int count);

}  // namespace vkpose
