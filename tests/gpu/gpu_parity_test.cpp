// GPU kernels == CPU reference, bit for bit, for every integer stage: label images of both
// modalities at every level, the linear memories, and the matches.
#include <algorithm>
#include <cstdlib>

#include "gpu/batch.hpp"
#include "match/depth_gate.hpp"
#include "match/features.hpp"
#include "match/frame_features_gpu.hpp"
#include "match/match_geometry.hpp"
#include "match/matcher.hpp"
#include "test_support.hpp"
#include "vkpose/bank.hpp"
#include "vkpose/device.hpp"

namespace vkpose {
namespace {

int countDifferent(const cv::Mat& a, const cv::Mat& b) {
  cv::Mat diff;
  cv::compare(a, b, diff, cv::CMP_NE);
  return cv::countNonZero(diff);
}

void expectFeatureParity(const LinemodFrame& frame, const FeatureParams& params, const std::string& name) {
  const auto reference = quantizeFramePyramid(frame, params);
  auto templates = std::vector<LinemodTemplate>{};
  const auto layouts = match::makeLayouts(templates, params, frame.bgr.cols, frame.bgr.rows);
  gpu::FrameFeatures features(test::context(), params);
  gpu::Batch batch(test::context());
  const int outside = MatchParams{}.outside_response;
  features.record(batch, frame, layouts, outside);
  std::vector<QuantizedLevel> gpu_levels;
  features.downloadLabels(batch, gpu_levels);
  std::vector<std::vector<uint8_t>> gpu_memory(layouts.size());
  for (std::size_t l = 0; l < layouts.size(); ++l) {
    gpu_memory[l].resize(layouts[l].total_bytes() / 2);
    batch.download(features.memory(l), gpu_memory[l].data(), gpu_memory[l].size());
  }
  batch.submit();
  // The GPU memories hold a nibble per cell: back to a byte per cell, as the reference
  // writes them.
  for (std::size_t l = 0; l < layouts.size(); ++l) {
    std::vector<uint8_t> cells(layouts[l].total_bytes());
    for (std::size_t c = 0; c < cells.size(); ++c) cells[c] = (gpu_memory[l][c / 2] >> (4 * (c % 2))) & 0xF;
    gpu_memory[l] = std::move(cells);
  }
  for (std::size_t l = 0; l < reference.size(); ++l) {
    for (int m = 0; m < kModalityCount; ++m) {
      if (reference[l].labels[m].empty()) continue;
      EXPECT_EQ(countDifferent(gpu_levels[l].labels[m], reference[l].labels[m]), 0)
          << name << ": level " << l << " modality " << m << " labels differ";
    }
    std::vector<uint8_t> cpu_memory(layouts[l].total_bytes(), static_cast<uint8_t>(outside));
    for (int m = 0; m < kModalityCount; ++m)
      if (!reference[l].labels[m].empty())
        linearizeResponseMaps(computeResponseMaps(spreadLabels(reference[l].labels[m], layouts[l].T)), m, layouts[l],
                              cpu_memory);
    EXPECT_TRUE(cpu_memory == gpu_memory[l]) << name << ": level " << l << " linear memories differ";
  }
}

// Parity holds on any frame: without ../shared/data synthetic scenes stand in for the real ones.
TEST(GpuParity, FrameFeaturesOnRealFrames) {
  expectFeatureParity(test::lmoFrameOrStandIn(), {}, test::frameName("LM-O"));
  expectFeatureParity(test::icbinFrameOrStandIn(), {}, test::frameName("IC-BIN"));
}

TEST(GpuParity, FrameFeaturesOnOddSizes) {
  for (cv::Size size : {cv::Size(127, 93), cv::Size(17, 13), cv::Size(2, 2), cv::Size(641, 3)}) {
    LinemodFrame f;
    f.bgr.create(size, CV_8UC3);
    cv::randu(f.bgr, 0, 256);
    f.depth_mm.create(size, CV_16UC1);
    cv::randu(f.depth_mm, 500, 540);
    FeatureParams p;
    p.T = {3, 7};
    expectFeatureParity(f, p, std::to_string(size.width) + "x" + std::to_string(size.height));
  }
}

TEST(GpuParity, FrameFeaturesPastTheWorkgroupLimitOfOneDispatchDimension) {
  // Regression: 2600 x 1950 = 5.07 Mpixels needs 79,219 workgroups of 64, more than one
  // dimension of a dispatch holds on lavapipe (65,535), and was refused with "too many
  // workgroups" (so was 4000 x 3000); the frame kernels now lay their workgroups out in rows.
  // A random frame: every part of it, the rows past the first 65,535 workgroups too, has labels.
  LinemodFrame f;
  f.bgr.create(1950, 2600, CV_8UC3);
  cv::randu(f.bgr, 0, 256);
  f.depth_mm.create(1950, 2600, CV_16UC1);
  cv::randu(f.depth_mm, 500, 540);
  expectFeatureParity(f, {}, "2600x1950");
  LinemodMatcher matcher(test::context());
  matcher.setTemplates(test::templatesFrom(f, {}, 2));
  EXPECT_NO_THROW(matcher.match(f));
}

// `first_run`, when given, receives the matcher's timings of its first run of the frame.
void expectMatchParity(const LinemodFrame& frame, const FeatureParams& params, int template_count, float threshold,
                       int copies = 1, MatchTimings* first_run = nullptr) {
  auto templates = test::templatesFrom(frame, params, template_count);
  ASSERT_GT(templates.size(), 10u);
  const auto originals = templates;
  for (int c = 1; c < copies; ++c) templates.insert(templates.end(), originals.begin(), originals.end());
  MatchParams mp;
  mp.threshold = threshold;
  const auto reference = matchTemplatesReference(quantizeFramePyramid(frame, params), templates, params, mp);
  LinemodMatcher matcher(test::context(), params, mp);
  matcher.setTemplates(templates);
  const auto ours = matcher.match(frame);
  EXPECT_GT(reference.size(), 0u);
  ASSERT_EQ(ours.size(), reference.size());
  for (std::size_t i = 0; i < ours.size(); ++i) ASSERT_EQ(ours[i], reference[i]) << "match " << i;
  EXPECT_GE(matcher.lastTimings().attempts, matcher.lastTimings().passes);
  if (first_run) *first_run = matcher.lastTimings();
  // A second run of the same frame gives the very same matches, and starts with the buffer
  // sizes and pass size the first one ended with: nothing overflows and runs again.
  EXPECT_EQ(matcher.match(frame), ours);
  EXPECT_EQ(matcher.lastTimings().attempts, matcher.lastTimings().passes);
  EXPECT_GE(matcher.lastTimings().passes, 1u);
  // Features and similarity share a submit where the queue has timestamps; both still get
  // their own time.
  EXPECT_GT(matcher.lastTimings().features_ms, 0.0);
  EXPECT_GT(matcher.lastTimings().similarity_ms, 0.0);
}

TEST(GpuBatch, TimestampsTimeTheWorkBetweenThem) {
  gpu::Batch batch(test::context());
  if (!batch.timestamps()) GTEST_SKIP() << "this device's compute queue writes no timestamps";
  gpu::Buffer buffer(test::context(), std::size_t{32} << 20);
  const uint32_t before = batch.timestamp();
  for (int i = 0; i < 4; ++i) batch.fill(buffer, static_cast<uint32_t>(i));
  const uint32_t after = batch.timestamp();
  batch.submit();
  const double ms = batch.millisecondsBetween(before, after);
  EXPECT_GT(ms, 0.0) << "filling 128 MiB took no time";
  EXPECT_LT(ms, 60'000.0);
  EXPECT_EQ(batch.millisecondsBetween(after, after), 0.0);  // one timestamp: no time between
  EXPECT_THROW(batch.millisecondsBetween(before, after + 1), std::logic_error);
  // The next submit starts a fresh set.
  batch.fill(buffer, 0u);
  batch.submit();
  EXPECT_THROW(batch.millisecondsBetween(before, after), std::logic_error);
}

TEST(GpuParity, MatchesOnRealFramesBothModalities) {
  expectMatchParity(test::lmoFrameOrStandIn(), {}, 60, 80.0f);
  expectMatchParity(test::icbinFrameOrStandIn(), {}, 60, 80.0f);
}

TEST(GpuParity, MatchesAcrossSeveralTemplateChunks) {
  // A chunk takes up to 16,384 templates; when its refinement units outgrow one binding of
  // unit scores, the matcher halves the chunks and runs the frame again. A low limit on the
  // units (VKPOSE_MAX_REFINE_UNITS) makes 60 copies of 40 templates split several times.
  struct LowUnitLimit {
    LowUnitLimit() { ::setenv("VKPOSE_MAX_REFINE_UNITS", "3000", 1); }
    ~LowUnitLimit() { ::unsetenv("VKPOSE_MAX_REFINE_UNITS"); }
  } limit;
  MatchTimings first_run;
  expectMatchParity(test::lmoFrameOrStandIn(), {}, 40, 92.0f, 60, &first_run);
  EXPECT_GT(first_run.chunks, 1u);
  EXPECT_GT(first_run.attempts, first_run.passes);
}

TEST(GpuParity, MatchesWithOneModalityAndOneLevel) {
  FeatureParams colour_only;
  colour_only.use_depth = false;
  expectMatchParity(test::lmoFrameOrStandIn(), colour_only, 40, 75.0f);
  FeatureParams one_level;
  one_level.T = {4};
  expectMatchParity(test::lmoFrameOrStandIn(), one_level, 30, 85.0f);
}

// A template cut by the left border: the features outside the image count the outside
// response (MatchParams::outside_response). Each template is cut where a fifth of its
// finest-level features fall outside: at 0 (OpenCV's rule) its own view can no longer pass
// (4/5 of the features inside reach 3.2 of the 3.6 a feature that 80 % asks), at the default
// 3 it passes again where it lies. At 4 a feature outside counts as a perfect response, so no
// position scores less than at 3 and the view still passes; but the finer level reports each
// coarse cell's best position only, and that can be one farther out of the image (more of the
// template outside, each feature at 4): the synthetic stand-in's frame does so. GPU and CPU
// reference agree on the cut frame at 0, 3, 4.
TEST(GpuParity, AViewCutByTheBorderCountsItsFeaturesOutsideAtTheOutsideResponse) {
  const auto frame = test::lmoFrameOrStandIn();
  const FeatureParams params;
  const auto templates = test::templatesFrom(frame, params, 30);
  ASSERT_GT(templates.size(), 10u);
  MatchParams mp;
  ASSERT_EQ(mp.outside_response, 3);
  const auto whole = matchTemplatesReference(quantizeFramePyramid(frame, params), templates, params, mp);
  int tried = 0, found_at_default = 0;
  for (std::size_t t = 0; t < templates.size() && tried < 3; ++t) {
    // Its own view: the template's best match on the whole frame, near 100 %.
    const auto own = std::find_if(whole.begin(), whole.end(), [&](const Match& m) {
      return m.template_id == static_cast<int>(t) && m.similarity > 97.f;
    });
    if (own == whole.end()) continue;
    std::vector<int> xs;
    for (const auto& f : templates[t].levels[0].features) xs.push_back(f.x);
    std::sort(xs.begin(), xs.end());
    const int cut = xs[xs.size() / 5] + 1;  // features left of `cut` fall outside
    const int x0 = own->x + cut;
    if (cut <= 0 || x0 <= 0 || x0 >= frame.bgr.cols / 2) continue;
    ++tried;
    const cv::Rect keep(x0, 0, frame.bgr.cols - x0, frame.bgr.rows);
    const LinemodFrame cropped{frame.bgr(keep).clone(), frame.depth_mm(keep).clone()};
    const std::vector<LinemodTemplate> one{templates[t]};
    const auto pyramid = quantizeFramePyramid(cropped, params);
    float at_default = 0.f;
    for (const int outside : {0, 3, 4}) {
      mp.outside_response = outside;
      const auto reference = matchTemplatesReference(pyramid, one, params, mp);
      LinemodMatcher matcher(test::context(), params, mp);
      matcher.setTemplates(one);
      EXPECT_EQ(matcher.match(cropped), reference) << "template " << t << ", outside response " << outside;
      float at_place = 0.f, best = 0.f;  // similarity within 5 px of its own view, and anywhere
      for (const Match& m : reference) {
        best = std::max(best, m.similarity);
        if (std::abs(m.x - (own->x - x0)) <= 5 && std::abs(m.y - own->y) <= 5) at_place = std::max(at_place, m.similarity);
      }
      if (outside == 0) {
        EXPECT_EQ(at_place, 0.f) << "template " << t << " cut at " << cut << " px passed at 0";
      } else if (outside == 3) {
        found_at_default += at_place > 0.f;
        at_default = at_place;
      } else {
        EXPECT_GE(best, at_default) << "template " << t << " cut at " << cut << " px: best " << best
                                    << " % at 4, less than " << at_default << " % at its place at 3";
      }
    }
  }
  ASSERT_GT(tried, 0) << "no template had its own view far enough from the left border";
  EXPECT_EQ(found_at_default, tried);
}

TEST(GpuParity, TemplatesWithMoreThan63FeaturesUse16BitSums) {
  const auto frame = test::lmoFrameOrStandIn();
  auto templates = test::templatesFrom(frame, {}, 20);
  ASSERT_FALSE(templates.empty());
  // Merge templates pairwise into ones with 126+ features per modality per level.
  std::vector<LinemodTemplate> big;
  for (std::size_t i = 0; i + 1 < templates.size(); i += 2) {
    LinemodTemplate t = templates[i];
    for (std::size_t l = 0; l < t.levels.size(); ++l) {
      const auto& other = templates[i + 1].levels[l];
      t.levels[l].width = std::max(t.levels[l].width, other.width);
      t.levels[l].height = std::max(t.levels[l].height, other.height);
      t.levels[l].features.insert(t.levels[l].features.end(), other.features.begin(), other.features.end());
    }
    big.push_back(t);
  }
  ASSERT_GT(big.front().levels[0].features.size(), 200u);
  MatchParams mp;
  mp.threshold = 50.0f;
  const auto reference = matchTemplatesReference(quantizeFramePyramid(frame, {}), big, {}, mp);
  LinemodMatcher matcher(test::context(), {}, mp);
  matcher.setTemplates(big);
  EXPECT_EQ(matcher.match(frame), reference);
  EXPECT_GT(reference.size(), 0u);
  // Raw scores above 255 prove the sums did not wrap at 8 bits.
  int max_raw = 0;
  for (const auto& m : reference) max_raw = std::max(max_raw, m.raw_score);
  EXPECT_GT(max_raw, 255);
}

// Depth gates for templates cut from a frame: the anchor at the template's centre, training
// distances taking turns over `distances` (metres), a 10 cm object, 10 cm apart.
std::vector<match::TemplateDepthGate> gatesFor(const std::vector<LinemodTemplate>& templates,
                                               const FeatureParams& params, const std::vector<float>& distances) {
  std::vector<match::TemplateDepthGate> gates;
  for (std::size_t i = 0; i < templates.size(); ++i) {
    BankTemplate t;
    t.distance = distances[i % distances.size()];
    t.anchor_x = 0.5f * static_cast<float>(templates[i].levels[0].width);
    t.anchor_y = 0.5f * static_cast<float>(templates[i].levels[0].height);
    gates.push_back(match::templateDepthGate(t, 0.1f, 0.1f, params));
  }
  match::numberDepthBands(gates);
  return gates;
}

// Issue 21's parity test: with depth-guided pruning the GPU gives exactly the matches of the
// reference whose coarse positions pass the depth test, a subset of the unpruned matches;
// the counts it reports are the brute-force counts.
void expectPrunedParity(const LinemodFrame& frame, const std::vector<float>& distances, int template_count,
                        const std::string& name, bool expect_skips = true) {
  const FeatureParams params;
  auto templates = test::templatesFrom(frame, params, template_count);
  ASSERT_GT(templates.size(), 10u);
  MatchParams mp;
  mp.threshold = 75.0f;
  DepthPruning pruning;
  pruning.gates = gatesFor(templates, params, distances);
  const auto layouts = match::makeLayouts(templates, params, frame.bgr.cols, frame.bgr.rows);
  pruning.cells = match::anchorDepthCells(frame.depth_mm, layouts.back(), static_cast<int>(layouts.size()) - 1);
  const auto pyramid = quantizeFramePyramid(frame, params);
  const auto unpruned = matchTemplatesReference(pyramid, templates, params, mp);
  const auto reference = matchTemplatesReference(pyramid, templates, params, mp, &pruning);
  EXPECT_GT(reference.size(), 0u) << name;
  EXPECT_LT(reference.size(), unpruned.size()) << name << ": nothing was pruned";

  LinemodMatcher matcher(test::context(), params, mp);
  matcher.setTemplates(templates, pruning.gates);
  const auto ours = matcher.match(frame);
  ASSERT_EQ(ours.size(), reference.size()) << name;
  for (std::size_t i = 0; i < ours.size(); ++i) ASSERT_EQ(ours[i], reference[i]) << name << ": match " << i;
  for (const auto& m : ours) EXPECT_NE(std::find(unpruned.begin(), unpruned.end(), m), unpruned.end()) << name;

  // The counts, against a walk over every template's every position.
  uint64_t pairs = 0, pruned = 0;
  for (std::size_t t = 0; t < templates.size(); ++t) {
    const auto& level = templates[t].levels.back();
    const auto range = match::coarseRange(
        level, layouts.back(), match::rawThreshold(static_cast<int>(level.features.size()), mp.threshold),
        mp.outside_response);
    for (int r = range.r_lo; r < range.r_lo + range.rows; ++r)
      for (int c = range.c_lo; c < range.c_lo + range.columns; ++c) {
        ++pairs;
        if (!match::positionPasses(pruning.cells, pruning.gates[t], r, c)) ++pruned;
      }
  }
  const auto& timings = matcher.lastTimings();
  EXPECT_EQ(timings.pairs, pairs) << name;
  EXPECT_EQ(timings.pairs_pruned, pruned) << name;
  EXPECT_GT(timings.pairs_pruned, 0u) << name;
  if (expect_skips) {
    EXPECT_GT(timings.pairs_skipped, 0u) << name << ": no strip was skipped unread";
  }
  EXPECT_LE(timings.pairs_skipped, timings.pairs_pruned) << name;

  // Switched off, the matcher scores everything again.
  MatchParams off = mp;
  off.depth_pruning = false;
  LinemodMatcher unpruned_matcher(test::context(), params, off);
  unpruned_matcher.setTemplates(templates, pruning.gates);
  EXPECT_EQ(unpruned_matcher.match(frame), unpruned) << name;
  EXPECT_EQ(unpruned_matcher.lastTimings().pairs, 0u) << name;
}

TEST(GpuParity, DepthPrunedMatchesAreTheUnprunedOnesThatPassTheDepthTest) {
  // IC-BIN's frame spans about 0.7 to 1.7 m; LM-O's about 0.6 to 1.3 m (their stand-ins, a
  // camera 0.6 to 1.2 m above a table or bin, about the same).
  expectPrunedParity(test::icbinFrameOrStandIn(), {0.6f, 0.8f, 1.0f, 1.4f, 2.5f}, 60, test::frameName("IC-BIN"));
  expectPrunedParity(test::lmoFrameOrStandIn(), {0.5f, 0.8f, 1.1f, 2.0f}, 60, test::frameName("LM-O"));
  // Half the depth gone: those cells keep every template (and every strip has some).
  LinemodFrame half = test::icbinFrameOrStandIn();
  half.depth_mm(cv::Rect(0, 0, half.depth_mm.cols / 2, half.depth_mm.rows)).setTo(0);
  expectPrunedParity(half, {0.6f, 1.0f, 2.5f}, 60, "IC-BIN, left half without depth", false);
}

}  // namespace
}  // namespace vkpose
