// LINEMOD's scattered feature selection (training), exact and fast: see scattered.hpp.
#include "training/scattered.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <climits>
#include <cmath>
#include <cstdint>
#include <utility>
#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace vkpose {

namespace {

/// Candidates best first, ties in their order (as std::stable_sort by score would leave
/// them): a stable LSD radix sort, a byte a pass, of the scores' bits inverted. Scores are
/// not negative (gradient magnitudes, distances), and their bits then order as they do. A
/// view's depth candidates are every pixel of its eroded mask (thousands): four linear passes
/// instead of a comparison sort.
void sortBestFirst(std::vector<FeatureCandidate>& candidates) {
  const std::size_t n = candidates.size();
  if (n < 2) return;
  std::vector<uint32_t> key(n), key_tmp(n);
  std::vector<uint32_t> index(n), index_tmp(n);
  for (std::size_t i = 0; i < n; ++i) {
    const float score = candidates[i].score > 0.f ? candidates[i].score : 0.f;  // -0 ties +0
    key[i] = ~std::bit_cast<uint32_t>(score);
    index[i] = static_cast<uint32_t>(i);
  }
  for (int shift = 0; shift < 32; shift += 8) {
    std::array<std::size_t, 257> start{};
    for (std::size_t i = 0; i < n; ++i) ++start[((key[i] >> shift) & 0xFFu) + 1];
    if (start[((key[0] >> shift) & 0xFFu) + 1] == n) continue;  // one value in this byte: order kept
    for (std::size_t b = 1; b < start.size(); ++b) start[b] += start[b - 1];
    for (std::size_t i = 0; i < n; ++i) {
      const std::size_t at = start[(key[i] >> shift) & 0xFFu]++;
      key_tmp[at] = key[i];
      index_tmp[at] = index[i];
    }
    key.swap(key_tmp);
    index.swap(index_tmp);
  }
  std::vector<FeatureCandidate> sorted(n);
  for (std::size_t i = 0; i < n; ++i) sorted[i] = candidates[index[i]];
  candidates = std::move(sorted);
}

/// From `i` on, the first candidate whose nearest_sq is at least d2 (or the last few, fewer
/// than 8, to be looked at one by one), passing over blocks of 8 that hold none; `best_left`
/// takes the largest value passed over (taken ones are -1). Most candidates are blocked, so
/// this is most of a pass: four lanes at a time where SSE is there.
std::size_t skipBlocked(const std::vector<float>& nearest_sq, std::size_t i, float d2, float& best_left) {
  const std::size_t n = nearest_sq.size();
#if defined(__SSE2__)
  const __m128 limit = _mm_set1_ps(d2);
  __m128 most = _mm_set1_ps(best_left);
  for (; i + 8 <= n; i += 8) {
    const __m128 a = _mm_loadu_ps(&nearest_sq[i]), b = _mm_loadu_ps(&nearest_sq[i + 4]);
    if (_mm_movemask_ps(_mm_or_ps(_mm_cmpge_ps(a, limit), _mm_cmpge_ps(b, limit)))) break;
    most = _mm_max_ps(most, _mm_max_ps(a, b));
  }
  alignas(16) float lanes[4];
  _mm_store_ps(lanes, most);
  best_left = std::max({lanes[0], lanes[1], lanes[2], lanes[3]});
#else
  for (; i + 8 <= n; i += 8) {
    bool any = false;
    float most = best_left;
    for (std::size_t k = i; k < i + 8; ++k) {
      any |= nearest_sq[k] >= d2;
      most = std::max(most, nearest_sq[k]);
    }
    if (any) break;
    best_left = most;
  }
#endif
  return i;
}

}  // namespace

/// LINEMOD's scattered selection: best first, each new feature at least `distance` from
/// those already taken; the distance relaxes by one pixel after every pass. Each candidate's
/// distance to the nearest taken feature is kept up to date, and passes that could take
/// nothing are skipped, which gives the same choice as the plain loop in O(count * n).
///
/// Only the candidates that may lie within the current distance of a newly taken one are
/// updated (found through a grid of 8 x 8 pixel buckets, row by row over the circle's span): a
/// candidate farther away keeps a stale squared distance, but stale and true are then both at
/// least the current distance^2, and that distance only shrinks, so every comparison (may it
/// be taken, and the largest blocked distance left) comes out as with the true value.
std::vector<FeatureCandidate> selectScattered(std::vector<FeatureCandidate> candidates, int count) {
  sortBestFirst(candidates);
  if (static_cast<int>(candidates.size()) <= count) return candidates;
  constexpr int kBucket = 8;
  int min_x = INT32_MAX, min_y = INT32_MAX, max_x = INT32_MIN, max_y = INT32_MIN;
  for (const auto& c : candidates) {
    min_x = std::min(min_x, c.x);
    min_y = std::min(min_y, c.y);
    max_x = std::max(max_x, c.x);
    max_y = std::max(max_y, c.y);
  }
  const int buckets_x = (max_x - min_x) / kBucket + 1, buckets_y = (max_y - min_y) / kBucket + 1;
  auto bucketOf = [&](const FeatureCandidate& c) { return (c.y - min_y) / kBucket * buckets_x + (c.x - min_x) / kBucket; };
  // FeatureCandidate indices by bucket (a counting sort), with their positions beside them.
  std::vector<int> first(static_cast<std::size_t>(buckets_x) * buckets_y + 1, 0), members(candidates.size());
  std::vector<float> member_x(candidates.size()), member_y(candidates.size());
  for (const auto& c : candidates) ++first[bucketOf(c) + 1];
  for (std::size_t b = 1; b < first.size(); ++b) first[b] += first[b - 1];
  {
    std::vector<int> fill(first.begin(), first.end() - 1);
    for (std::size_t i = 0; i < candidates.size(); ++i) {
      const int k = fill[bucketOf(candidates[i])]++;
      members[k] = static_cast<int>(i);
      member_x[k] = static_cast<float>(candidates[i].x);
      member_y[k] = static_cast<float>(candidates[i].y);
    }
  }
  std::vector<FeatureCandidate> chosen;
  constexpr float kFar = 1e30f;
  std::vector<float> nearest_sq(candidates.size(), kFar);  // < 0: taken (and min() keeps it so)
  float distance = static_cast<float>(candidates.size() / static_cast<std::size_t>(count) + 1);
  while (static_cast<int>(chosen.size()) < count) {
    const float d2 = distance * distance;
    float best_left = -1.f;
    for (std::size_t i = 0; i < candidates.size() && static_cast<int>(chosen.size()) < count; ++i) {
      i = skipBlocked(nearest_sq, i, d2, best_left);
      if (i >= candidates.size()) break;
      if (nearest_sq[i] < 0.f) continue;
      if (nearest_sq[i] < d2) {
        best_left = std::max(best_left, nearest_sq[i]);
        continue;
      }
      const FeatureCandidate& taken = candidates[i];
      chosen.push_back(taken);
      nearest_sq[i] = -1.f;
      const float tx = static_cast<float>(taken.x), ty = static_cast<float>(taken.y);
      const int by0 = std::max(0, static_cast<int>(std::floor((ty - distance - static_cast<float>(min_y)) / kBucket)));
      const int by1 =
          std::min(buckets_y - 1, static_cast<int>(std::floor((ty + distance - static_cast<float>(min_y)) / kBucket)));
      for (int by = by0; by <= by1; ++by) {
        // The bucket row's rows nearest the taken one bound dy; columns beyond the circle's
        // half-width there are farther than the distance.
        const float row_lo = static_cast<float>(min_y + by * kBucket), row_hi = row_lo + (kBucket - 1);
        const float dy = std::max({0.f, row_lo - ty, ty - row_hi});
        if (dy * dy >= d2) continue;
        const float half = std::sqrt(d2 - dy * dy);
        const int bx0 = std::max(0, static_cast<int>(std::floor((tx - half - static_cast<float>(min_x)) / kBucket)));
        const int bx1 =
            std::min(buckets_x - 1, static_cast<int>(std::floor((tx + half - static_cast<float>(min_x)) / kBucket)));
        if (bx0 > bx1) continue;
        // The buckets of a row are contiguous in `members`.
        for (int k = first[by * buckets_x + bx0], end = first[by * buckets_x + bx1 + 1]; k < end; ++k) {
          const float ex = member_x[k] - tx, ey = member_y[k] - ty;
          float& slot = nearest_sq[static_cast<std::size_t>(members[k])];
          slot = std::min(slot, ex * ex + ey * ey);
        }
      }
    }
    distance -= 1.f;  // at distance 1 every untaken candidate qualifies, so this ends
    // Skip the passes that would take nothing: the next one that takes something is the
    // first whose distance^2 is at most the largest distance^2 left (these are integers).
    if (best_left >= 0.f && best_left < distance * distance)
      distance = std::max(1.f, std::floor(std::sqrt(best_left) + 1e-4f));
  }
  return chosen;
}

}  // namespace vkpose
