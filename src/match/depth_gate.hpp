#pragma once
// Depth-guided pruning of the coarse similarity pass (issue 21): a template trained at
// distance d can only show an object whose surface is about d away, so where the frame has
// depth it is scored only at positions whose anchor cell (the coarse cell its object centre
// falls in; outside the frame, the nearest edge cell) holds a depth within the template's
// gate. A cell's depth spans it and its eight neighbours (refinement moves a coarse match by
// up to half a cell); a neighbourhood without depth keeps every template.
//
// Templates of one object and distance share a gate, a depth band. Per frame, each band gets
// the bounding box of the anchor cells that meet it; the GPU kernel clips each template's
// range of positions to its band's box (positions outside cannot pass), skips the strips
// (kStripRows x kStripColumns positions, what one invocation scores) of the clipped range
// whose cells all miss, both before reading any memory, and tests each passing position's own
// cell before appending it. The CPU reference filters positions with the same test, so the
// two give the same matches.
#include <cstdint>
#include <utility>
#include <vector>

#include <opencv2/core.hpp>

#include "match/features.hpp"
#include "vkpose/bank.hpp"

namespace vkpose::match {

struct CoarseRange;  // match/match_geometry.hpp

/// Positions one coarse invocation scores: rows x columns (ROWS and 16 * SPAN in
/// shaders/similarity_coarse.comp). Strips are what pruning can skip.
constexpr int kStripRows = 2;
constexpr int kStripColumns = 48;

/// Where a template may be scored.
struct TemplateDepthGate {
  /// Coarse cells from the template's position to the cell its anchor (object centre) is in.
  int anchor_dc = 0, anchor_dr = 0;
  /// Scene depths, millimetres, the template's training distance allows at the anchor.
  int z_lo_mm = 0, z_hi_mm = 0xFFFF;
  /// Index of its (z_lo_mm, z_hi_mm) among the distinct ones (numberDepthBands).
  int band = 0;
};

/// Numbers the distinct depth intervals of `gates` (sets each gate's band) and returns them.
std::vector<std::pair<int, int>> numberDepthBands(std::vector<TemplateDepthGate>& gates);

/// The gate of one bank template: its training distance d, +- (the object's radius plus half
/// the bank's distance step, at least 5 % of d), at the coarse cell of its anchor.
TemplateDepthGate templateDepthGate(const BankTemplate& t, float diameter_m, float distance_step_m,
                                    const FeatureParams& features);

/// Every template of `banks`, in concatenateTemplates' order.
std::vector<TemplateDepthGate> templateDepthGates(const std::vector<TemplateBank>& banks);

/// Depth intervals of a frame's coarse cells. An interval packs the least depth in its low
/// and the greatest in its high 16 bits (mm); one whose 3 x 3 neighbourhood has a cell without
/// depth is (0, 0xFFFF), which meets every gate. Plane 0 holds each cell's interval over its
/// neighbourhood; plane 1 + k the union of rows r and r + 1 over
/// columns c .. c + 2^k - 1 (clipped to the grid): a strip's interval is the union of two
/// entries of one plane, as a sparse table gives it.
struct AnchorDepthCells {
  int cells_x = 0, cells_y = 0;
  int cell_px = 0;  ///< level-0 pixels per cell side
  int levels = 0;   ///< planes 1 .. levels
  std::vector<uint32_t> planes;
  bool empty() const { return planes.empty(); }
  std::size_t index(int plane, int r, int c) const {
    return (static_cast<std::size_t>(plane) * static_cast<std::size_t>(cells_y) + static_cast<std::size_t>(r)) *
               static_cast<std::size_t>(cells_x) +
           static_cast<std::size_t>(c);
  }
  uint32_t at(int plane, int r, int c) const { return planes[index(plane, r, c)]; }
};

/// Sparse-table planes needed for windows of up to kStripColumns cells.
int anchorDepthLevels();

/// The cells of `coarse` (the coarsest level's layout, `coarse_level` halvings below the
/// frame) from a CV_16UC1 depth image in mm. Empty when the depth is empty or all zero.
AnchorDepthCells anchorDepthCells(const cv::Mat& depth_mm, const LinearMemoryLayout& coarse, int coarse_level);

/// Whether a packed interval meets a gate.
inline bool intervalMeets(uint32_t interval, const TemplateDepthGate& g) {
  return static_cast<int>(interval & 0xFFFFu) <= g.z_hi_mm && static_cast<int>(interval >> 16) >= g.z_lo_mm;
}

/// Whether the template may match at coarse position (r, c): its anchor cell (clamped to the
/// grid) has no depth or a depth within the gate. The test both matchers apply.
bool positionPasses(const AnchorDepthCells& cells, const TemplateDepthGate& g, int r, int c);

/// Whether any position of the strip of `rows` x `columns` positions from (r, c) may pass:
/// the GPU's skip test (conservative: a one-row strip is tested with the next row too).
bool stripMayPass(const AnchorDepthCells& cells, const TemplateDepthGate& g, int r, int c, int rows, int columns);

/// Bounding box of the anchor cells that meet a band, rows [r0, r1) and columns [c0, c1); a
/// side on the grid's edge is open (kOpen), as anchors beyond it take the edge cell's depth.
/// Empty (r0 == r1) when no cell meets it.
constexpr int kOpen = 1 << 20;
struct BandBox {
  int r0 = -kOpen, r1 = kOpen, c0 = -kOpen, c1 = kOpen;
};
std::vector<BandBox> bandBoxes(const AnchorDepthCells& cells, const std::vector<std::pair<int, int>>& bands);

/// A template's range of positions clipped to its band's box: what the kernel scans.
CoarseRange clipToBox(const CoarseRange& range, const TemplateDepthGate& g, const BandBox& box);

/// (template, position) pairs of a frame's coarse pass: all of them, those pruned, and those
/// in strips skipped whole (no memory read).
struct PruningCount {
  uint64_t pairs = 0, pruned = 0, skipped = 0;
};
PruningCount countPruning(const AnchorDepthCells& cells, const std::vector<TemplateDepthGate>& gates,
                          const std::vector<BandBox>& boxes, const std::vector<CoarseRange>& ranges);

}  // namespace vkpose::match
