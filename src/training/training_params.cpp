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

namespace {
/// Pixels per cell of LINEMOD's coarsest level (2^(levels - 1) * T), 0 without levels.
double coarseCellPixels(const TrainingParams& params) {
  const std::vector<int>& T = params.features.T;
  return T.empty() ? 0.0 : static_cast<double>(1 << (T.size() - 1)) * T.back();
}
}  // namespace

PartSizeEvidence partSizeEvidence(const Mesh& mesh, const TrainingParams& params) {
  PartSizeEvidence e;
  e.diameter_m = mesh.diameter;
  Eigen::Vector3f extent = mesh.bbox_max - mesh.bbox_min;
  std::sort(extent.data(), extent.data() + 3);
  e.thinnest_m = extent[0];
  e.width_m = extent[1];
  e.nearest_m = params.views.radii.low();
  e.farthest_m = std::max(params.views.radii.from, params.views.radii.to);
  const float f = 0.5f * static_cast<float>(params.camera.fx + params.camera.fy);
  const float cell = static_cast<float>(coarseCellPixels(params));
  if (!(f > 0.f && e.nearest_m > 0.f)) return e;
  e.pixels_near = f * e.diameter_m / e.nearest_m;
  e.pixels_far = f * e.diameter_m / e.farthest_m;
  e.thin_pixels_far = f * e.thinnest_m / e.farthest_m;
  e.cells_near = cell > 0.f ? e.pixels_near / cell : 0.f;
  e.cells_far = cell > 0.f ? e.pixels_far / cell : 0.f;
  e.width_cells_near = cell > 0.f ? f * e.width_m / e.nearest_m / cell : 0.f;
  e.pixel_mm_near = 1e3f * e.nearest_m / f;
  e.pixel_mm_far = 1e3f * e.farthest_m / f;
  return e;
}

std::string PartSizeEvidence::summary() const {
  // "a-b" from the farthest distance's figure to the nearest's, one figure where they are one.
  const auto span = [](float far, float near, int decimals) {
    const std::string a = fmt::format("{:.{}f}", far, decimals), b = fmt::format("{:.{}f}", near, decimals);
    return a == b ? a : a + "-" + b;
  };
  std::string s = fmt::format(
      "{:.0f} mm across is {} pixels at {} m ({} cells of LINEMOD's coarsest level); a pixel spans {} mm there",
      1e3f * diameter_m, span(pixels_far, pixels_near, 0), span(farthest_m, nearest_m, 2),
      span(cells_far, cells_near, 1), span(pixel_mm_far, pixel_mm_near, 2));
  if (thin_in_depth())
    s += fmt::format(
        ". Its thinnest side, {:.1f} mm, is {:.1f} pixels at {:.2f} m: a structured-light or stereo sensor's "
        "matching window (7-9 pixels) merges it into what lies behind, so its depth shows little of it",
        1e3f * thinnest_m, thin_pixels_far, farthest_m);
  return s;
}

std::string PartSizeEvidence::refusal() const {
  if (cells_near >= kMinPartCells && line_like()) {
    // Where the part would span one cell: width * f / distance = one cell's pixels.
    const float within_m = width_cells_near > 0.f ? nearest_m * width_cells_near / kMinWidthCells : 0.f;
    return fmt::format(
        "{:.1f} mm wide at {:.2f} m is {:.1f} cells of LINEMOD's coarsest level, under the {:.0f} a part needs: "
        "there it is a line, and LINEMOD's orientations, which have no polarity, find it along every straight "
        "edge, rod and bin rim of a scene (a 48 mm M3 screw at 0.3-0.5 m: 11-51 wrong a pile, none right). "
        "Train (and detect) within {:.2f} m, with a longer focal length, or pass --allow-small to train it anyway",
        1e3f * width_m, nearest_m, width_cells_near, kMinWidthCells, within_m);
  }
  return fmt::format(
      "{:.0f} mm across at {:.2f} m is {:.0f} pixels, {:.1f} cells of LINEMOD's coarsest level, under the {:.0f} "
      "a part needs to be told from its neighbourhood: its few features fit any screw head or part end, and a "
      "bank of it finds them everywhere. Train (and detect) nearer, with a longer focal length, or pass "
      "--allow-small to train it anyway",
      1e3f * diameter_m, nearest_m, pixels_near, cells_near, kMinPartCells);
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
