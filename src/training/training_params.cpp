// Training parameters and the bank's template list: what the bank reader needs, apart from
// the GPU training itself (the fuzz build links the readers without the GPU layer).
#include <fmt/format.h>

#include "vkpose/bank.hpp"
#include "vkpose/error.hpp"
#include "vkpose/geometry.hpp"

namespace vkpose {

void validateTrainingParams(const TrainingParams& p) {
  validateViewSampling(p.views);
  validateFeatureParams(p.features);
  validateCamera(p.camera, "training camera");
  if (p.features_per_modality < 4 || p.features_per_modality > 4096)
    throw InputError(fmt::format("features: {} per modality; use 4 to 4096", p.features_per_modality));
  if (!(p.near_symmetry_tolerance >= 0.f && p.near_symmetry_tolerance <= 0.2f))
    throw InputError(fmt::format("near-symmetry tolerance {} must be in [0, 0.2] (a share of the diameter)",
                                 p.near_symmetry_tolerance));
  if (!(p.strong_threshold > 0.f && p.strong_threshold < 2000.f))
    throw InputError(fmt::format("strong threshold {} must be in (0, 2000)", p.strong_threshold));
}

std::vector<LinemodTemplate> TemplateBank::linemodTemplates() const {
  std::vector<LinemodTemplate> out;
  out.reserve(templates.size());
  for (const auto& t : templates) out.push_back(t.linemod);
  return out;
}

}  // namespace vkpose
