#include "match/depth_gate.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <map>
#include <utility>

#include "match/match_geometry.hpp"

namespace vkpose::match {

namespace {
constexpr uint32_t kNoDepth = 0xFFFF0000u;  // least 0, greatest 0xFFFF: meets every gate

uint32_t unite(uint32_t a, uint32_t b) {
  return std::min(a & 0xFFFFu, b & 0xFFFFu) | (std::max(a >> 16, b >> 16) << 16);
}

int floorLog2(int v) { return std::bit_width(static_cast<unsigned>(v)) - 1; }
}  // namespace

TemplateDepthGate templateDepthGate(const BankTemplate& t, float diameter_m, float distance_step_m,
                                    const FeatureParams& features) {
  TemplateDepthGate g;
  const int L = static_cast<int>(features.T.size()) - 1;
  const int Tc = features.T.back();
  const int cell_px = Tc << L;
  // A coarse position c reports pixel c * Tc + positionOffset(Tc) at its level, about
  // (that << L) + half a coarse pixel at level 0 (refineWindowStart's convention); the anchor
  // lies anchor_x further, in the cell floor(x / cell_px).
  const int origin = (positionOffset(Tc) << L) + ((1 << L) >> 1);
  g.anchor_dc = floorDiv(origin + static_cast<int>(std::floor(t.anchor_x)), cell_px);
  g.anchor_dr = floorDiv(origin + static_cast<int>(std::floor(t.anchor_y)), cell_px);
  // The surface at the anchor lies within a radius of the centre; a template matches objects
  // up to about half a distance step nearer or further (the next distance's templates take
  // over there), and at least 5 % either way when the bank has one distance.
  const float tolerance = 0.5f * diameter_m + trainedDistanceAllowance(distance_step_m, t.distance);
  g.z_lo_mm = std::max(0, static_cast<int>(std::floor((t.distance - tolerance) * 1000.f)));
  g.z_hi_mm = std::min(0xFFFF, static_cast<int>(std::ceil((t.distance + tolerance) * 1000.f)));
  return g;
}

std::vector<TemplateDepthGate> templateDepthGates(const std::vector<TemplateBank>& banks) {
  std::vector<TemplateDepthGate> gates;
  for (const auto& bank : banks) {
    const auto& radii = bank.params.views.radii;
    const float step = radii.values().size() > 1 ? radii.step : 0.f;
    for (const auto& t : bank.templates)
      gates.push_back(templateDepthGate(t, bank.diameter, step, bank.params.features));
  }
  numberDepthBands(gates);
  return gates;
}

std::vector<std::pair<int, int>> numberDepthBands(std::vector<TemplateDepthGate>& gates) {
  std::vector<std::pair<int, int>> bands;
  std::map<std::pair<int, int>, int> index;
  for (auto& g : gates) {
    const auto [it, inserted] = index.try_emplace({g.z_lo_mm, g.z_hi_mm}, static_cast<int>(bands.size()));
    if (inserted) bands.push_back(it->first);
    g.band = it->second;
  }
  return bands;
}

int anchorDepthLevels() { return floorLog2(kStripColumns) + 1; }

AnchorDepthCells anchorDepthCells(const cv::Mat& depth_mm, const LinearMemoryLayout& coarse, int coarse_level) {
  AnchorDepthCells out;
  if (depth_mm.empty() || depth_mm.type() != CV_16UC1 || cv::countNonZero(depth_mm) == 0) return out;
  out.cells_x = coarse.cells_x;
  out.cells_y = coarse.cells_y;
  out.cell_px = coarse.T << coarse_level;
  out.levels = anchorDepthLevels();
  const std::size_t plane = static_cast<std::size_t>(out.cells_x) * static_cast<std::size_t>(out.cells_y);
  out.planes.assign(plane * static_cast<std::size_t>(1 + out.levels), kNoDepth);
  // Plane 0: least and greatest depth of each cell's pixels (0xFFFF, 0 until one is seen).
  std::vector<uint32_t> lo(plane, 0xFFFFu), hi(plane, 0u);
  for (int y = 0; y < depth_mm.rows; ++y) {
    const int r = y / out.cell_px;
    if (r >= out.cells_y) break;
    const auto* row = depth_mm.ptr<uint16_t>(y);
    for (int x = 0; x < depth_mm.cols; ++x) {
      const int c = x / out.cell_px;
      if (c >= out.cells_x) break;
      if (row[x] == 0) continue;
      const std::size_t i = static_cast<std::size_t>(r) * static_cast<std::size_t>(out.cells_x) + static_cast<std::size_t>(c);
      lo[i] = std::min<uint32_t>(lo[i], row[x]);
      hi[i] = std::max<uint32_t>(hi[i], row[x]);
    }
  }
  // Each cell's interval joins its eight neighbours': refinement moves a coarse match by up to
  // half its 16 x 16 fine-cell window, so the object centre may lie a cell away.
  for (int r = 0; r < out.cells_y; ++r)
    for (int c = 0; c < out.cells_x; ++c) {
      uint32_t interval = 0xFFFFu;  // empty: least 0xFFFF, greatest 0
      for (int dr = -1; dr <= 1; ++dr)
        for (int dc = -1; dc <= 1; ++dc) {
          const int rr = r + dr, cc = c + dc;
          if (rr < 0 || cc < 0 || rr >= out.cells_y || cc >= out.cells_x) continue;
          const std::size_t j = static_cast<std::size_t>(rr) * static_cast<std::size_t>(out.cells_x) + static_cast<std::size_t>(cc);
          interval = hi[j] > 0 ? unite(interval, lo[j] | (hi[j] << 16)) : kNoDepth;
          if (interval == kNoDepth) break;
        }
      out.planes[static_cast<std::size_t>(r) * static_cast<std::size_t>(out.cells_x) + static_cast<std::size_t>(c)] = interval;
    }
  // Plane 1: rows r and r + 1; plane 1 + k: columns c .. c + 2^k - 1 of plane k.
  for (int r = 0; r < out.cells_y; ++r)
    for (int c = 0; c < out.cells_x; ++c)
      out.planes[out.index(1, r, c)] = r + 1 < out.cells_y ? unite(out.at(0, r, c), out.at(0, r + 1, c)) : out.at(0, r, c);
  for (int k = 1; k < out.levels; ++k)
    for (int r = 0; r < out.cells_y; ++r)
      for (int c = 0; c < out.cells_x; ++c) {
        const int next = c + (1 << (k - 1));
        out.planes[out.index(1 + k, r, c)] = next < out.cells_x ? unite(out.at(k, r, c), out.at(k, r, next)) : out.at(k, r, c);
      }
  return out;
}

bool positionPasses(const AnchorDepthCells& cells, const TemplateDepthGate& g, int r, int c) {
  if (cells.empty()) return true;
  const int ra = std::clamp(r + g.anchor_dr, 0, cells.cells_y - 1), ca = std::clamp(c + g.anchor_dc, 0, cells.cells_x - 1);
  return intervalMeets(cells.at(0, ra, ca), g);
}

bool stripMayPass(const AnchorDepthCells& cells, const TemplateDepthGate& g, int r, int c, int rows, int columns) {
  if (cells.empty() || rows <= 0 || columns <= 0) return true;
  // The anchor cells clamped to the grid are the clamped window.
  const int r0 = std::clamp(r + g.anchor_dr, 0, cells.cells_y - 1);
  const int c0 = std::clamp(c + g.anchor_dc, 0, cells.cells_x - 1);
  const int c1 = std::clamp(c + g.anchor_dc + columns - 1, 0, cells.cells_x - 1);
  // Plane 1 unites rows r0 and r0 + 1: for a strip of one row (or one clamped to the last
  // row) a wider interval, which only ever keeps a strip that could have been skipped.
  const int width = c1 - c0 + 1;
  const int k = floorLog2(width);
  const uint32_t interval = unite(cells.at(1 + k, r0, c0), cells.at(1 + k, r0, c1 + 1 - (1 << k)));
  return intervalMeets(interval, g);
}

std::vector<BandBox> bandBoxes(const AnchorDepthCells& cells, const std::vector<std::pair<int, int>>& bands) {
  std::vector<BandBox> boxes(bands.size());
  if (cells.empty()) return boxes;
  for (std::size_t b = 0; b < bands.size(); ++b) {
    TemplateDepthGate g;
    g.z_lo_mm = bands[b].first;
    g.z_hi_mm = bands[b].second;
    int r0 = cells.cells_y, r1 = 0, c0 = cells.cells_x, c1 = 0;
    for (int r = 0; r < cells.cells_y; ++r)
      for (int c = 0; c < cells.cells_x; ++c)
        if (intervalMeets(cells.at(0, r, c), g)) {
          r0 = std::min(r0, r);
          r1 = std::max(r1, r + 1);
          c0 = std::min(c0, c);
          c1 = std::max(c1, c + 1);
        }
    if (r1 == 0) {
      boxes[b] = {0, 0, 0, 0};
      continue;
    }
    boxes[b] = {r0 == 0 ? -kOpen : r0, r1 == cells.cells_y ? kOpen : r1, c0 == 0 ? -kOpen : c0,
                c1 == cells.cells_x ? kOpen : c1};
  }
  return boxes;
}

CoarseRange clipToBox(const CoarseRange& range, const TemplateDepthGate& g, const BandBox& box) {
  CoarseRange out;
  out.r_lo = std::max(range.r_lo, box.r0 - g.anchor_dr);
  out.c_lo = std::max(range.c_lo, box.c0 - g.anchor_dc);
  out.rows = std::max(0, std::min(range.r_lo + range.rows, box.r1 - g.anchor_dr) - out.r_lo);
  out.columns = std::max(0, std::min(range.c_lo + range.columns, box.c1 - g.anchor_dc) - out.c_lo);
  if (out.rows == 0 || out.columns == 0) out.rows = out.columns = 0;
  return out;
}

PruningCount countPruning(const AnchorDepthCells& cells, const std::vector<TemplateDepthGate>& gates,
                          const std::vector<BandBox>& boxes, const std::vector<CoarseRange>& ranges) {
  PruningCount count;
  for (const auto& range : ranges) count.pairs += static_cast<uint64_t>(range.rows) * static_cast<uint64_t>(range.columns);
  if (cells.empty() || gates.size() != ranges.size()) return count;
  // Pruned pairs: per band, a summed-area table of the anchor cells that miss it, over the
  // grid widened by the largest anchor offsets (cells beyond the grid take the edge cell's).
  const int W = cells.cells_x, H = cells.cells_y;
  int margin = 0;
  for (std::size_t t = 0; t < gates.size(); ++t) {
    const auto& g = gates[t];
    const auto& range = ranges[t];
    margin = std::max({margin, std::abs(range.r_lo + g.anchor_dr), std::abs(range.c_lo + g.anchor_dc),
                       std::abs(range.r_lo + range.rows + g.anchor_dr - H),
                       std::abs(range.c_lo + range.columns + g.anchor_dc - W)});
  }
  margin += 1;
  const int SW = W + 2 * margin, SH = H + 2 * margin;  // summed-area grid: cell (r, c) at (r + margin, c + margin)
  std::map<int, std::vector<uint32_t>> misses;
  auto sat_at = [&](const std::vector<uint32_t>& sat, int r, int c) {
    return sat[static_cast<std::size_t>(r) * static_cast<std::size_t>(SW + 1) + static_cast<std::size_t>(c)];
  };
  for (std::size_t t = 0; t < gates.size(); ++t) {
    const auto& g = gates[t];
    auto [it, inserted] = misses.try_emplace(g.band);
    auto& sat = it->second;
    if (inserted) {
      sat.assign(static_cast<std::size_t>((SW + 1) * (SH + 1)), 0u);
      for (int r = 0; r < SH; ++r)
        for (int c = 0; c < SW; ++c) {
          const int rr = std::clamp(r - margin, 0, H - 1), cc = std::clamp(c - margin, 0, W - 1);
          const uint32_t miss = intervalMeets(cells.at(0, rr, cc), g) ? 0u : 1u;
          sat[static_cast<std::size_t>((r + 1) * (SW + 1) + c + 1)] =
              miss + sat_at(sat, r, c + 1) + sat_at(sat, r + 1, c) - sat_at(sat, r, c);
        }
    }
    const auto& range = ranges[t];
    if (range.rows <= 0 || range.columns <= 0) continue;
    const int r0 = range.r_lo + g.anchor_dr + margin, r1 = r0 + range.rows;
    const int c0 = range.c_lo + g.anchor_dc + margin, c1 = c0 + range.columns;
    count.pruned += sat_at(sat, r1, c1) - sat_at(sat, r0, c1) - sat_at(sat, r1, c0) + sat_at(sat, r0, c0);
    // Skipped: outside the band's box, and strips of the clipped range, as the kernel walks them.
    const auto clipped = g.band < static_cast<int>(boxes.size()) ? clipToBox(range, g, boxes[static_cast<std::size_t>(g.band)]) : range;
    uint64_t scanned = 0;
    for (int band = 0; band * kStripRows < clipped.rows; ++band)
      for (int span = 0; span * kStripColumns < clipped.columns; ++span) {
        const int rows = std::min(kStripRows, clipped.rows - band * kStripRows);
        const int columns = std::min(kStripColumns, clipped.columns - span * kStripColumns);
        if (stripMayPass(cells, g, clipped.r_lo + band * kStripRows, clipped.c_lo + span * kStripColumns, rows, columns))
          scanned += static_cast<uint64_t>(rows) * static_cast<uint64_t>(columns);
      }
    count.skipped += static_cast<uint64_t>(range.rows) * static_cast<uint64_t>(range.columns) - scanned;
  }
  return count;
}

}  // namespace vkpose::match
