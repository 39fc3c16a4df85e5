// Depth-guided pruning on the CPU (match/depth_gate.hpp): the anchor cells of a depth image,
// the strip and box tests the GPU skips by (never skipping a position that passes), and the
// counts.
#include <random>

#include <gtest/gtest.h>

#include "match/depth_gate.hpp"
#include "match/match_geometry.hpp"

namespace vkpose {
namespace {

// A 160 x 96 frame at T = {5, 8}: coarse cells are 16 level-0 pixels, 10 x 6 of them.
LinearMemoryLayout coarseLayout() { return makeLinearMemoryLayout(80, 48, 8, 4, 0); }

cv::Mat rampDepth() {
  cv::Mat depth(96, 160, CV_16UC1);
  for (int y = 0; y < depth.rows; ++y)
    for (int x = 0; x < depth.cols; ++x) depth.at<uint16_t>(y, x) = static_cast<uint16_t>(500 + 5 * x + y);
  return depth;
}

TEST(DepthGate, AnchorCellsHoldTheLeastAndGreatestDepthAroundEachCell) {
  cv::Mat depth = rampDepth();
  depth(cv::Rect(32, 16, 16, 16)).setTo(0);  // cell (1, 2) has no depth
  const auto cells = match::anchorDepthCells(depth, coarseLayout(), 1);
  ASSERT_EQ(cells.cells_x, 10);
  ASSERT_EQ(cells.cells_y, 6);
  EXPECT_EQ(cells.cell_px, 16);
  // A cell's interval spans it and its eight neighbours (pixels 0-31 for cell (0, 0)).
  EXPECT_EQ(cells.at(0, 0, 0), 500u | ((500u + 5u * 31u + 31u) << 16));
  EXPECT_EQ(cells.at(0, 4, 8), (500u + 5u * 112u + 48u) | ((500u + 5u * 159u + 95u) << 16));
  // Next to a cell without depth, every gate is met.
  EXPECT_EQ(cells.at(0, 1, 2), 0xFFFF0000u);
  EXPECT_EQ(cells.at(0, 0, 3), 0xFFFF0000u);
  EXPECT_NE(cells.at(0, 0, 4), 0xFFFF0000u);
  // Plane 1 + k: rows r, r + 1 over 2^k columns (cells (0..1, 0) reach pixels 0-31 x 0-47).
  EXPECT_EQ(cells.at(1, 0, 0), 500u | ((500u + 5u * 31u + 47u) << 16));
  EXPECT_EQ(cells.at(3, 2, 4) & 0xFFFFu, 500u + 5u * 48u + 16u);
  EXPECT_EQ(cells.at(3, 2, 4) >> 16, 500u + 5u * 143u + 79u);
  EXPECT_TRUE(match::anchorDepthCells(cv::Mat::zeros(96, 160, CV_16UC1), coarseLayout(), 1).empty());
  EXPECT_TRUE(match::anchorDepthCells(cv::Mat(), coarseLayout(), 1).empty());
}

TEST(DepthGate, GateFollowsTheTrainingDistanceAndTheAnchor) {
  BankTemplate t;
  t.distance = 0.8f;
  t.anchor_x = 40.f;
  t.anchor_y = 20.f;
  const auto g = match::templateDepthGate(t, 0.1f, 0.1f, FeatureParams{});
  EXPECT_NEAR(g.z_lo_mm, 700, 1);  // 0.8 - (0.05 + 0.05)
  EXPECT_NEAR(g.z_hi_mm, 900, 1);
  // Coarse position 0 reports level-1 pixel 3, level 0 about 7; the anchor at 47 / 27.
  EXPECT_EQ(g.anchor_dc, 2);
  EXPECT_EQ(g.anchor_dr, 1);
  // One distance: at least 5 % of it either way besides the radius.
  const auto single = match::templateDepthGate(t, 0.1f, 0.f, FeatureParams{});
  EXPECT_NEAR(single.z_lo_mm, 710, 1);
  EXPECT_NEAR(single.z_hi_mm, 890, 1);
}

// Whatever strip or box the GPU would skip holds no position that passes.
TEST(DepthGate, SkipsNeverDropAPassingPosition) {
  cv::Mat depth = rampDepth();
  depth(cv::Rect(96, 48, 32, 16)).setTo(0);
  const auto cells = match::anchorDepthCells(depth, coarseLayout(), 1);
  std::mt19937 rng(5);
  std::uniform_int_distribution<int> offset(-3, 3), z(450, 1400), width(1, match::kStripColumns);
  std::uniform_int_distribution<int> position(-4, 12);
  int skipped = 0, kept = 0;
  for (int trial = 0; trial < 4000; ++trial) {
    match::TemplateDepthGate g;
    g.anchor_dc = offset(rng);
    g.anchor_dr = offset(rng);
    g.z_lo_mm = z(rng);
    g.z_hi_mm = g.z_lo_mm + 60;
    const int r = position(rng), c = position(rng), rows = 1 + trial % 2, columns = width(rng);
    bool any = false;
    for (int dr = 0; dr < rows; ++dr)
      for (int dc = 0; dc < columns; ++dc) any = any || match::positionPasses(cells, g, r + dr, c + dc);
    const bool may = match::stripMayPass(cells, g, r, c, rows, columns);
    if (any) {
      EXPECT_TRUE(may) << "trial " << trial << ": a strip with a passing position was skipped";
    }
    (may ? kept : skipped)++;
  }
  EXPECT_GT(skipped, 100);
  EXPECT_GT(kept, 100);
  // Band boxes: a range clipped to its box loses only positions that fail.
  std::vector<match::TemplateDepthGate> gates(3);
  gates[0].z_lo_mm = 500, gates[0].z_hi_mm = 560;    // the left columns
  gates[1].z_lo_mm = 3000, gates[1].z_hi_mm = 3100;  // nowhere, but the cells without depth
  gates[2].z_lo_mm = 1200, gates[2].z_hi_mm = 1300;  // the right columns
  const auto bands = match::numberDepthBands(gates);
  ASSERT_EQ(bands.size(), 3u);
  const auto boxes = match::bandBoxes(cells, bands);
  EXPECT_EQ(boxes[0].c0, -match::kOpen);
  EXPECT_LT(boxes[0].c1, 10);
  // The cells without depth (row 3, columns 6-7) and their neighbours.
  EXPECT_EQ(boxes[1].r0, 2);
  EXPECT_EQ(boxes[1].r1, 5);
  EXPECT_EQ(boxes[1].c0, 5);
  EXPECT_EQ(boxes[1].c1, 9);
  EXPECT_EQ(boxes[2].c1, match::kOpen);
  for (std::size_t b = 0; b < gates.size(); ++b) {
    const match::CoarseRange range{-2, -1, 14, 9};
    const auto clipped = match::clipToBox(range, gates[b], boxes[b]);
    for (int r = range.r_lo; r < range.r_lo + range.rows; ++r)
      for (int c = range.c_lo; c < range.c_lo + range.columns; ++c) {
        const bool inside = r >= clipped.r_lo && r < clipped.r_lo + clipped.rows && c >= clipped.c_lo &&
                            c < clipped.c_lo + clipped.columns;
        if (!inside) {
          EXPECT_FALSE(match::positionPasses(cells, gates[b], r, c)) << "band " << b << " at " << r << ", " << c;
        }
      }
    EXPECT_LT(clipped.rows * clipped.columns, range.rows * range.columns) << "band " << b;
  }
}

TEST(DepthGate, CountsAreTheBruteForceCounts) {
  const auto cells = match::anchorDepthCells(rampDepth(), coarseLayout(), 1);
  std::vector<match::TemplateDepthGate> gates;
  std::vector<match::CoarseRange> ranges;
  for (int i = 0; i < 12; ++i) {
    match::TemplateDepthGate g;
    g.anchor_dc = i % 4 - 1;
    g.anchor_dr = i % 3;
    g.z_lo_mm = 500 + 80 * i;
    g.z_hi_mm = g.z_lo_mm + 150;
    gates.push_back(g);
    ranges.push_back({-1 + i % 2, -2 + i % 3, 9 + i % 3, 5 + i % 2});
  }
  gates[5].z_lo_mm = 5000, gates[5].z_hi_mm = 5100;  // no cell: the whole range skipped
  const auto bands = match::numberDepthBands(gates);
  const auto boxes = match::bandBoxes(cells, bands);
  EXPECT_EQ(boxes[static_cast<std::size_t>(gates[5].band)].r1, 0);
  const auto count = match::countPruning(cells, gates, boxes, ranges);
  uint64_t pairs = 0, pruned = 0;
  for (std::size_t t = 0; t < gates.size(); ++t)
    for (int r = ranges[t].r_lo; r < ranges[t].r_lo + ranges[t].rows; ++r)
      for (int c = ranges[t].c_lo; c < ranges[t].c_lo + ranges[t].columns; ++c) {
        ++pairs;
        pruned += match::positionPasses(cells, gates[t], r, c) ? 0 : 1;
      }
  EXPECT_EQ(count.pairs, pairs);
  EXPECT_EQ(count.pruned, pruned);
  EXPECT_GT(count.pruned, 0u);
  EXPECT_GE(count.skipped, static_cast<uint64_t>(ranges[5].rows * ranges[5].columns));
  EXPECT_LE(count.skipped, count.pruned);
}

}  // namespace
}  // namespace vkpose
