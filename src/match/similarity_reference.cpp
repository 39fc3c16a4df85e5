// Similarity, CPU reference (LINEMOD section 2.5, OpenCV's Detector::matchClass with the
// border fixed). shaders/similarity_coarse.comp and similarity_refine.comp compute the same
// candidates and refinements.
#include <algorithm>
#include <bit>
#include <cstdint>
#include <tuple>

#include "match/features.hpp"
#include "match/match_geometry.hpp"
#include "match/matcher.hpp"
#include "util/radix_sort.hpp"
#include "vkpose/bank.hpp"
#include "vkpose/error.hpp"

namespace vkpose {

void sortMatches(std::vector<Match>& matches) {
  std::sort(matches.begin(), matches.end(), [](const Match& a, const Match& b) {
    return std::tie(b.similarity, a.template_id, a.y, a.x) < std::tie(a.similarity, b.template_id, b.y, b.x);
  });
}

namespace match {

std::vector<Match> finishMatches(const std::vector<CoarseCandidate>& candidates, const std::vector<RefineResult>& refined,
                                 const std::vector<LinemodTemplate>& templates, const FeatureParams& fp,
                                 const MatchParams& params) {
  const std::size_t coarse = fp.T.size() - 1;
  const int Tc = fp.T[coarse];
  // The scoring level's feature count of each template, gathered once: a frame can have
  // millions of candidates, and reaching each template's features through its levels would
  // cost a few cache misses per candidate.
  std::vector<int> feature_counts(templates.size());
  for (std::size_t t = 0; t < templates.size(); ++t) feature_counts[t] = featureCount(templates[t], 0);
  std::vector<Match> out;
  out.reserve(candidates.size());
  for (std::size_t i = 0; i < candidates.size(); ++i) {
    const auto& cand = candidates[i];
    const int features = feature_counts[static_cast<std::size_t>(cand.template_id)];
    Match m;
    m.template_id = cand.template_id;
    if (coarse == 0) {
      // Without refinement OpenCV reports the coarse score rounded up by half a percent.
      m.x = cand.c * Tc + positionOffset(Tc);
      m.y = cand.r * Tc + positionOffset(Tc);
      m.raw_score = cand.score;
      m.similarity = similarityPercent(cand.score, features) + 0.5f;
    } else {
      const auto& ref = refined[i];
      if (ref.score == 0) continue;
      const int Tf = fp.T[0];
      m.x = (refineWindowStart(cand.c, Tc, Tf) + ref.best_c) * Tf + positionOffset(Tf);
      m.y = (refineWindowStart(cand.r, Tc, Tf) + ref.best_r) * Tf + positionOffset(Tf);
      m.raw_score = ref.score;
      m.similarity = similarityPercent(ref.score, features);
      if (m.similarity < params.threshold) continue;
    }
    out.push_back(m);
  }
  sortDistinctMatches(out);
  return out;
}

void sortDistinctMatches(std::vector<Match>& matches) {
  if (matches.empty()) return;
  // Candidates whose refinements land on the same position of a template give the same match
  // (a frame of many objects: 4 million matches, a fifth of them distinct). Template and
  // position packed into a 64-bit key with the match's index below, radix-sorted: repeats
  // become neighbours, and the distinct matches come out by template, y and x, for a
  // fraction of sorting the matches themselves. A stable radix sort by similarity then gives
  // sortMatches' order.
  int min_x = matches[0].x, max_x = min_x, min_y = matches[0].y, max_y = min_y, max_t = 0;
  for (const Match& m : matches) {
    min_x = std::min(min_x, m.x), max_x = std::max(max_x, m.x);
    min_y = std::min(min_y, m.y), max_y = std::max(max_y, m.y);
    max_t = std::max(max_t, m.template_id);
  }
  auto bits = [](std::uint64_t v) { return static_cast<int>(std::bit_width(v)); };
  const int bx = bits(std::uint64_t(max_x - min_x)), by = bits(std::uint64_t(max_y - min_y));
  const int bt = bits(std::uint64_t(max_t));
  if (!util::fitsWithIndex(bx + by + bt, matches.size())) {  // never at camera sizes; the plain way
    sortMatches(matches);
    matches.erase(std::unique(matches.begin(), matches.end(),
                              [](const Match& a, const Match& b) {
                                return a.template_id == b.template_id && a.x == b.x && a.y == b.y;
                              }),
                  matches.end());
    return;
  }
  std::vector<std::uint64_t> places(matches.size());
  for (std::size_t i = 0; i < matches.size(); ++i) {
    const Match& m = matches[i];
    places[i] = (std::uint64_t(m.template_id) << (by + bx)) | (std::uint64_t(m.y - min_y) << bx) |
                std::uint64_t(m.x - min_x);
  }
  std::vector<Match> distinct;
  distinct.reserve(matches.size() / 4);
  std::uint64_t last = 0;
  for (const std::uint32_t i : util::stableOrder(places)) {
    if (distinct.empty() || places[i] != last) distinct.push_back(matches[i]);
    last = places[i];
  }
  // Best first: the similarity's bits made to sort as the floats do, inverted (equal
  // similarities stay in template, y, x order).
  std::vector<std::uint64_t> similarity(distinct.size());
  for (std::size_t i = 0; i < distinct.size(); ++i) {
    const auto raw = std::bit_cast<std::uint32_t>(distinct[i].similarity);
    similarity[i] = ~((raw & 0x80000000u) ? ~raw : raw | 0x80000000u) & 0xFFFFFFFFu;
  }
  matches.clear();
  for (const std::uint32_t i : util::stableOrder(similarity)) matches.push_back(distinct[i]);
}

}  // namespace match

void validateMatchParams(const MatchParams& params) {
  if (!(params.threshold > 0.0f && params.threshold <= 100.0f))
    throw InputError("match threshold " + std::to_string(params.threshold) + " % is outside (0, 100]");
  if (params.outside_response < 0 || params.outside_response > 4)
    throw InputError("the response of a feature outside the image must be 0..4, not " +
                     std::to_string(params.outside_response));
}

namespace {

/// Sum of responses of `level`'s features for a template at cells (r, c) .. (r, c + 15).
void scoreRow(const std::vector<uint8_t>& memory, const LinearMemoryLayout& layout, const TemplateLevel& level, int r,
              int c, int scores[match::kRefineWindow]) {
  const int T = layout.T;
  std::fill(scores, scores + match::kRefineWindow, 0);
  for (const auto& f : level.features) {
    const std::size_t base = layout.offset(static_cast<int>(f.modality), f.bin, f.y % T, f.x % T, f.y / T + r, f.x / T + c);
    for (int k = 0; k < match::kRefineWindow; ++k) scores[k] += memory[base + static_cast<std::size_t>(k)];
  }
}

}  // namespace

std::vector<Match> matchTemplatesReference(const std::vector<QuantizedLevel>& pyramid,
                                           const std::vector<LinemodTemplate>& templates,
                                           const FeatureParams& fp, const MatchParams& params,
                                           const DepthPruning* pruning) {
  validateFeatureParams(fp);
  if (pruning && pruning->gates.size() != templates.size())
    throw InputError("depth pruning needs one gate per template");
  validateTemplates(templates, fp);
  validateMatchParams(params);
  if (pyramid.size() != fp.T.size()) throw InputError("quantized pyramid has the wrong number of levels");
  const cv::Mat& level0 = pyramid[0].labels[fp.use_colour ? 0 : 1];
  const auto layouts = match::makeLayouts(templates, fp, level0.cols, level0.rows);

  // Linear memories of every level.
  std::vector<std::vector<uint8_t>> memories(pyramid.size());
  for (std::size_t l = 0; l < pyramid.size(); ++l) {
    memories[l].assign(layouts[l].total_bytes(), static_cast<uint8_t>(params.outside_response));
    for (int m = 0; m < kModalityCount; ++m)
      if (!pyramid[l].labels[m].empty())
        linearizeResponseMaps(computeResponseMaps(spreadLabels(pyramid[l].labels[m], layouts[l].T)), m, layouts[l],
                              memories[l]);
  }

  // Coarse level: every template at every position that can pass (match::coarseRange).
  const std::size_t coarse = pyramid.size() - 1;
  const auto& cl = layouts[coarse];
  std::vector<match::CoarseCandidate> candidates;
  int scores[match::kRefineWindow];
  for (std::size_t ti = 0; ti < templates.size(); ++ti) {
    const auto& level = templates[ti].levels[coarse];
    const int threshold = match::rawThreshold(static_cast<int>(level.features.size()), params.threshold);
    const auto range = match::coarseRange(level, cl, threshold, params.outside_response);
    for (int r = range.r_lo; r < range.r_lo + range.rows; ++r)
      for (int c0 = range.c_lo; c0 < range.c_lo + range.columns; c0 += match::kRefineWindow) {
        scoreRow(memories[coarse], cl, level, r, c0, scores);
        for (int k = 0; k < match::kRefineWindow && c0 + k < range.c_lo + range.columns; ++k)
          if (scores[k] > threshold && (!pruning || match::positionPasses(pruning->cells, pruning->gates[ti], r, c0 + k)))
            candidates.push_back({static_cast<int>(ti), r, c0 + k, scores[k]});
      }
  }

  // Finer level: the best position in a 16 x 16 cell window around each candidate.
  std::vector<match::RefineResult> refined;
  if (coarse == 1) {
    const auto& fl = layouts[0];
    for (const auto& cand : candidates) {
      const auto& level = templates[static_cast<std::size_t>(cand.template_id)].levels[0];
      const int sr = match::refineWindowStart(cand.r, cl.T, fl.T), sc = match::refineWindowStart(cand.c, cl.T, fl.T);
      match::RefineResult best;
      for (int row = 0; row < match::kRefineWindow; ++row) {
        scoreRow(memories[0], fl, level, sr + row, sc, scores);
        for (int col = 0; col < match::kRefineWindow; ++col)
          if (scores[col] > best.score) best = {scores[col], row, col};
      }
      refined.push_back(best);
    }
  }
  return match::finishMatches(candidates, refined, templates, fp, params);
}

}  // namespace vkpose
