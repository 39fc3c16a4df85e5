#pragma once
// Conventions shared by the CPU reference matcher and the GPU matcher, so the two cannot
// drift apart: position offsets, thresholds, refinement windows and memory layouts.
#include <algorithm>
#include <vector>

#include "match/features.hpp"
#include "match/matcher.hpp"
#include "vkpose/bank.hpp"

namespace vkpose::match {

/// Half of the refinement window, in cells: LINEMOD refines in a 16 x 16 cell window.
constexpr int kRefineHalf = 8;
constexpr int kRefineWindow = 2 * kRefineHalf;

/// Reported position of cell c at spreading step T: the one-sided T x T spreading window
/// means a template at cell c covers pixels c*T .. c*T+T-1; OpenCV reports c*T + this.
inline int positionOffset(int T) { return T / 2 + (T % 2 - 1); }

inline int floorDiv(int a, int b) { return a >= 0 ? a / b : -((-a + b - 1) / b); }

/// OpenCV's percent threshold as a raw score: 0 % is 2 per feature, 100 % is 4.
inline int rawThreshold(int feature_count, float threshold_percent) {
  return static_cast<int>(2 * feature_count + (threshold_percent / 100.f) * (2 * feature_count) + 0.5f);
}

inline float similarityPercent(int raw_score, int feature_count) {
  return (raw_score * 100.f) / (4 * feature_count);
}

/// The least raw score whose similarityPercent reaches `threshold_percent` (4 n + 1 when
/// none does): the finer level's pass test, in integers for the GPU, and exactly the host's.
inline int refinedPassScore(int feature_count, float threshold_percent) {
  int s = std::max(0, rawThreshold(feature_count, threshold_percent) - 4);
  while (s <= 4 * feature_count && similarityPercent(s, feature_count) < threshold_percent) ++s;
  while (s > 0 && similarityPercent(s - 1, feature_count) >= threshold_percent) --s;
  return s;
}

/// Coarse-level positions of a template: the cell positions whose template centre lies in
/// the image (OpenCV only tries templates lying wholly inside, and loses the border), less
/// those that cannot pass the threshold. A feature outside the image responds
/// `outside_response` (MatchParams) and a feature inside scores at most 4, so a position
/// with `inside` features of n scores at most 4 inside + outside_response (n - inside); the
/// range is trimmed, per axis, to the columns and rows where that can exceed
/// `raw_threshold`. With 0 and 80 % that is 90 % of the features inside, close to OpenCV's
/// wholly-inside range.
struct CoarseRange {
  int c_lo = 0, r_lo = 0;  ///< first cell column / row (may be negative)
  int columns = 0, rows = 0;  ///< 0 when no position can pass
};
CoarseRange coarseRange(const TemplateLevel& level, const LinearMemoryLayout& layout, int raw_threshold,
                        int outside_response);

/// Linear-memory layouts of every level for `templates` on a `width` x `height` frame.
std::vector<LinearMemoryLayout> makeLayouts(const std::vector<LinemodTemplate>& templates,
                                            const FeatureParams& params, int width, int height);

/// Size of each level: level 0 is the frame, each next level halves (rounding down).
std::vector<cv::Size> levelSizes(int width, int height, std::size_t levels);

}  // namespace vkpose::match

namespace vkpose::match {

/// A coarse-level position whose raw score passed the threshold.
struct CoarseCandidate {
  int template_id = 0;
  int r = 0, c = 0;  ///< template top-left, coarse cells
  int score = 0;
};

/// The best position of a candidate's refinement window at the finer level.
struct RefineResult {
  int score = 0;           ///< 0: nothing in the window
  int best_r = 0, best_c = 0;  ///< within the 16 x 16 window
};

/// Number of features of a template at a level.
inline int featureCount(const LinemodTemplate& t, std::size_t level) {
  return static_cast<int>(t.levels[level].features.size());
}

/// Coarse candidate -> full-resolution x or y of the finer level's window origin, in cells.
inline int refineWindowStart(int coarse_cell, int T_coarse, int T_fine) {
  const int coarse_px = coarse_cell * T_coarse + positionOffset(T_coarse);
  return floorDiv(2 * coarse_px + 1, T_fine) - kRefineHalf;
}

/// Turns candidates (and, with two levels, their refinement) into matches: positions,
/// percentages, threshold, duplicates removed, best first. Shared by CPU and GPU paths.
std::vector<Match> finishMatches(const std::vector<CoarseCandidate>& candidates, const std::vector<RefineResult>& refined,
                                 const std::vector<LinemodTemplate>& templates, const FeatureParams& feature_params,
                                 const MatchParams& params);

/// Keeps one of each template's matches at one position (repeats are equal) and sorts them
/// best first (sortMatches' order).
void sortDistinctMatches(std::vector<Match>& matches);

}  // namespace vkpose::match
