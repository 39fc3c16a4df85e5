// LINEMOD's scattered selection (training/scattered.hpp) against the plain loop it replaces
// (cv::linemod's selectScatteredFeatures: best first, each pass over all candidates taking those
// at least `distance` from every feature taken, the distance one pixel less after each pass), on
// random candidate sets: spread and crowded, ties in score, fewer candidates than asked for.
#include <gtest/gtest.h>

#include <algorithm>
#include <random>

#include "training/scattered.hpp"

namespace vkpose {
namespace {

std::vector<FeatureCandidate> plainLoop(std::vector<FeatureCandidate> candidates, int count) {
  std::stable_sort(candidates.begin(), candidates.end(),
                   [](const FeatureCandidate& a, const FeatureCandidate& b) { return a.score > b.score; });
  if (static_cast<int>(candidates.size()) <= count) return candidates;
  std::vector<FeatureCandidate> chosen;
  std::vector<bool> taken(candidates.size(), false);
  float distance = static_cast<float>(candidates.size() / static_cast<std::size_t>(count) + 1);
  while (static_cast<int>(chosen.size()) < count) {
    for (std::size_t i = 0; i < candidates.size() && static_cast<int>(chosen.size()) < count; ++i) {
      if (taken[i]) continue;
      bool keep = true;
      for (const FeatureCandidate& f : chosen) {
        const float dx = static_cast<float>(candidates[i].x - f.x), dy = static_cast<float>(candidates[i].y - f.y);
        keep = keep && dx * dx + dy * dy >= distance * distance;
      }
      if (keep) chosen.push_back(candidates[i]), taken[i] = true;
    }
    distance -= 1.f;
  }
  return chosen;
}

/// `n` distinct pixels in a w x h box, scores with many ties (quantized to `levels`).
std::vector<FeatureCandidate> randomCandidates(std::mt19937& rng, int n, int w, int h, int levels) {
  std::vector<int> pixels(static_cast<std::size_t>(w * h));
  for (std::size_t i = 0; i < pixels.size(); ++i) pixels[i] = static_cast<int>(i);
  std::shuffle(pixels.begin(), pixels.end(), rng);
  std::vector<FeatureCandidate> out;
  for (int i = 0; i < n; ++i) {
    const int p = pixels[static_cast<std::size_t>(i)];
    out.push_back({p % w + 3, p / w + 5, static_cast<uint8_t>(rng() % 8), static_cast<float>(rng() % levels) * 0.5f});
  }
  return out;
}

TEST(ScatteredSelection, ChoosesAsThePlainLoop) {
  std::mt19937 rng(7);
  int compared = 0;
  for (int trial = 0; trial < 300; ++trial) {
    const int w = 4 + static_cast<int>(rng() % 120), h = 4 + static_cast<int>(rng() % 120);
    const int n = 1 + static_cast<int>(rng() % std::min(w * h, 3000));
    const int count = 1 + static_cast<int>(rng() % 70);
    const int levels = trial % 3 == 0 ? 2 : 1000;  // mostly ties, or few
    const auto candidates = randomCandidates(rng, n, w, h, levels);
    const auto expected = plainLoop(candidates, count);
    const auto got = selectScattered(candidates, count);
    ASSERT_EQ(got.size(), expected.size()) << "trial " << trial;
    for (std::size_t i = 0; i < got.size(); ++i) {
      ASSERT_EQ(got[i].x, expected[i].x) << "trial " << trial << " feature " << i;
      ASSERT_EQ(got[i].y, expected[i].y) << "trial " << trial << " feature " << i;
      ASSERT_EQ(got[i].bin, expected[i].bin) << "trial " << trial << " feature " << i;
    }
    compared += n > count;
  }
  EXPECT_GT(compared, 200);  // most trials had more candidates than features to choose
}

TEST(ScatteredSelection, KeepsEveryCandidateWhenThereAreFewerThanAsked) {
  EXPECT_TRUE(selectScattered({}, 63).empty());
  EXPECT_EQ(selectScattered({{4, 2, 1, 0.f}}, 63).size(), 1u);
  const std::vector<FeatureCandidate> few = {{1, 1, 0, 2.f}, {5, 1, 1, 3.f}, {9, 9, 2, 3.f}};
  const auto got = selectScattered(few, 63);
  ASSERT_EQ(got.size(), 3u);
  EXPECT_EQ(got[0].x, 5);  // best first, ties in their order
  EXPECT_EQ(got[1].x, 9);
  EXPECT_EQ(got[2].x, 1);
}

}  // namespace
}  // namespace vkpose
