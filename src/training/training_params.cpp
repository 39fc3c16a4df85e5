// Training parameters and the bank's template list: what the bank reader needs, apart from
// the GPU training itself (the fuzz build links the readers without the GPU layer).
#include <algorithm>
#include <string>
#include <vector>

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

std::vector<std::string> trainingWarnings(const Mesh& mesh, const TrainingParams& params) {
  std::vector<std::string> warnings;
  // LINEMOD's coarsest level sees the object at 1 / 2^(levels - 1) of the resolution, in
  // cells of T pixels: below about 2.5 cells across, its views give few features and
  // detection falls off (docs/evaluation.md: a 20 mm part at 0.3-0.45 m, 1.6-2.4 cells,
  // F1 0.31; 40 mm, 3.2-4.8 cells, 0.62-0.83; LM-O's ape at 1.3 m, 2.8 cells).
  const std::vector<int>& T = params.features.T;
  if (T.empty()) return warnings;
  const double far = std::max(params.views.radii.from, params.views.radii.to);
  const double pixels = 0.5 * (params.camera.fx + params.camera.fy) * mesh.diameter / far;
  const double cells = pixels / (static_cast<double>(1 << (T.size() - 1)) * T.back());
  if (cells < 2.5)
    warnings.push_back(fmt::format(
        "{:.0f} mm across at {:.2f} m is {:.0f} pixels, {:.1f} cells of LINEMOD's coarsest level (T = {}): below "
        "about 2.5 cells, many views give too few features and detection falls off; train (and detect) nearer, "
        "or with a longer focal length",
        1e3 * mesh.diameter, far, pixels, cells, T.back()));
  return warnings;
}

std::vector<LinemodTemplate> TemplateBank::linemodTemplates() const {
  std::vector<LinemodTemplate> out;
  out.reserve(templates.size());
  for (const auto& t : templates) out.push_back(t.linemod);
  return out;
}

}  // namespace vkpose
