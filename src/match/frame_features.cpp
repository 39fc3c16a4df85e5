// Stage 1 entry points shared by the CPU reference and the GPU path: input validation and
// the CPU pyramid.
#include <algorithm>
#include <string>
#include <utility>
#include <vector>

#include "match/features.hpp"
#include "match/match_geometry.hpp"
#include "vkpose/error.hpp"

namespace vkpose {

void validateFeatureParams(const FeatureParams& p) {
  if (p.T.empty() || p.T.size() > 2)
    throw InputError("LINEMOD needs one or two pyramid levels (T), got " + std::to_string(p.T.size()));
  for (int t : p.T)
    if (t < 1 || t > 16) throw InputError("spreading step T = " + std::to_string(t) + " is outside 1..16");
  if (!p.use_colour && !p.use_depth) throw InputError("both LINEMOD modalities are switched off");
  if (!(p.weak_threshold >= 0.0f) || p.weak_threshold > 2000.0f)
    throw InputError("weak gradient threshold " + std::to_string(p.weak_threshold) + " is outside 0..2000");
  if (p.distance_threshold_mm < 1 || p.distance_threshold_mm > 65535)
    throw InputError("depth distance threshold " + std::to_string(p.distance_threshold_mm) + " mm is outside 1..65535");
  if (p.difference_threshold_mm < 1 || p.difference_threshold_mm > 10000)
    throw InputError("depth difference threshold " + std::to_string(p.difference_threshold_mm) +
                     " mm is outside 1..10000");
}

void validateFrame(const LinemodFrame& f, const FeatureParams& p) {
  if (p.use_colour) {
    if (f.bgr.empty()) throw InputError("the colour image is empty");
    if (f.bgr.type() != CV_8UC3) throw InputError("the colour image must be 8-bit with 3 channels");
  }
  if (p.use_depth) {
    if (f.depth_mm.empty()) throw InputError("the depth image is empty");
    if (f.depth_mm.type() != CV_16UC1) throw InputError("the depth image must be 16-bit with 1 channel");
  }
  if (p.use_colour && p.use_depth && f.bgr.size() != f.depth_mm.size())
    throw InputError("colour (" + std::to_string(f.bgr.cols) + "x" + std::to_string(f.bgr.rows) + ") and depth (" +
                     std::to_string(f.depth_mm.cols) + "x" + std::to_string(f.depth_mm.rows) +
                     ") images differ in size");
  const cv::Size size = p.use_colour ? f.bgr.size() : f.depth_mm.size();
  const int need = 1 << (p.T.size() - 1);
  if (size.width < need || size.height < need)
    throw InputError("a " + std::to_string(size.width) + "x" + std::to_string(size.height) +
                     " image is too small for " + std::to_string(p.T.size()) + " pyramid levels");
  if (size.width > 16384 || size.height > 16384)
    throw InputError("a " + std::to_string(size.width) + "x" + std::to_string(size.height) +
                     " image is larger than 16384 pixels on a side");
}

std::vector<QuantizedLevel> quantizeFramePyramid(const LinemodFrame& frame, const FeatureParams& params) {
  validateFeatureParams(params);
  validateFrame(frame, params);
  std::vector<QuantizedLevel> levels(params.T.size());
  cv::Mat bgr = frame.bgr;
  for (std::size_t l = 0; l < levels.size(); ++l) {
    levels[l].T = params.T[l];
    if (params.use_colour) {
      if (l > 0) bgr = pyrDownColour(bgr);
      levels[l].labels[0] = quantizeColourGradients(bgr, params.weak_threshold);
    }
    if (params.use_depth)
      levels[l].labels[1] = l == 0 ? quantizeDepthNormals(frame.depth_mm, params.distance_threshold_mm,
                                                          params.difference_threshold_mm)
                                   : downsampleLabels(levels[l - 1].labels[1]);
  }
  return levels;
}

namespace match {

std::vector<cv::Size> levelSizes(int width, int height, std::size_t levels) {
  std::vector<cv::Size> sizes;
  for (std::size_t l = 0; l < levels; ++l) {
    sizes.emplace_back(width, height);
    width /= 2;
    height /= 2;
  }
  return sizes;
}

namespace {
/// The [first, last] positions p of p_lo .. p_lo + count - 1 at which at least `need`
/// features (their cells counted in `below`: below[k] features have a cell < k) land inside
/// 0 .. cells - 1; first > last when none.
std::pair<int, int> positionsWithEnoughInside(const std::vector<int>& below, int p_lo, int count, int cells,
                                              int need) {
  const int span = static_cast<int>(below.size()) - 1;
  const auto cellsBelow = [&](int k) { return below[static_cast<std::size_t>(std::clamp(k, 0, span))]; };
  const auto inside = [&](int p) { return cellsBelow(cells - p) - cellsBelow(-p); };
  int first = p_lo, last = p_lo + count - 1;
  while (first <= last && inside(first) < need) ++first;
  while (last >= first && inside(last) < need) --last;
  return {first, last};
}

/// below[k]: how many of `cells` are < k, for k = 0 .. max cell + 1.
std::vector<int> cumulativeCounts(const std::vector<int>& cells) {
  std::vector<int> below(static_cast<std::size_t>(*std::max_element(cells.begin(), cells.end()) + 2), 0);
  for (const int c : cells) ++below[static_cast<std::size_t>(c) + 1];
  for (std::size_t k = 1; k < below.size(); ++k) below[k] += below[k - 1];
  return below;
}
}  // namespace

CoarseRange coarseRange(const TemplateLevel& level, const LinearMemoryLayout& layout, int raw_threshold,
                        int outside_response) {
  const int wf = templateCells(level.width, layout.T), hf = templateCells(level.height, layout.T);
  if (level.features.empty()) return {-(wf / 2), -(hf / 2), 0, 0};
  // 4 inside + o (n - inside) > threshold  <=>  (4 - o) inside > threshold - o n.
  const int excess = raw_threshold - outside_response * static_cast<int>(level.features.size());
  const int need = excess < 0 || outside_response >= 4 ? 0 : excess / (4 - outside_response) + 1;
  std::vector<int> xs, ys;
  xs.reserve(level.features.size());
  ys.reserve(level.features.size());
  for (const auto& f : level.features) {
    xs.push_back(f.x / layout.T);
    ys.push_back(f.y / layout.T);
  }
  const auto [c0, c1] = positionsWithEnoughInside(cumulativeCounts(xs), -(wf / 2), layout.cells_x, layout.cells_x, need);
  const auto [r0, r1] = positionsWithEnoughInside(cumulativeCounts(ys), -(hf / 2), layout.cells_y, layout.cells_y, need);
  if (c1 < c0 || r1 < r0) return {c0, r0, 0, 0};
  return {c0, r0, c1 - c0 + 1, r1 - r0 + 1};
}

std::vector<LinearMemoryLayout> makeLayouts(const std::vector<LinemodTemplate>& templates,
                                            const FeatureParams& params, int width, int height) {
  const auto sizes = levelSizes(width, height, params.T.size());
  std::vector<LinearMemoryLayout> layouts;
  for (std::size_t l = 0; l < sizes.size(); ++l) {
    const int T = params.T[l];
    int max_cells = 1;
    for (const auto& t : templates) {
      const auto& level = t.levels[l];
      max_cells = std::max({max_cells, templateCells(level.width, T), templateCells(level.height, T)});
      for (const auto& f : level.features) max_cells = std::max({max_cells, f.x / T + 1, f.y / T + 1});
    }
    // The finer levels refine within +-8 cells of a position mapped from the coarser level,
    // whose range follows the coarser level's template size.
    const int extra = l + 1 < sizes.size() ? kRefineHalf + 2 : 0;
    if (l + 1 < sizes.size())
      for (const auto& t : templates) {
        const int coarse_cells = std::max(templateCells(t.levels[l + 1].width, params.T[l + 1]),
                                          templateCells(t.levels[l + 1].height, params.T[l + 1]));
        max_cells = std::max(max_cells, (coarse_cells * params.T[l + 1] * 2 + T - 1) / T + 1);
      }
    layouts.push_back(makeLinearMemoryLayout(sizes[l].width, sizes[l].height, T, max_cells, extra));
  }
  return layouts;
}

}  // namespace match
}  // namespace vkpose
