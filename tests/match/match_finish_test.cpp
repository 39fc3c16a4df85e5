// The host's part of stage 2 after the GPU (match/match_geometry.hpp): the finer level's
// integer pass score the GPU lists refined candidates by, and removing repeated matches.
#include <algorithm>
#include <climits>
#include <random>

#include <gtest/gtest.h>

#include "match/match_geometry.hpp"

namespace vkpose {
namespace {

// refine_select.comp lists a refined candidate when its score reaches refinedPassScore; the
// host keeps a match when its similarityPercent reaches the threshold. They must agree on
// every score, or the GPU would drop matches the host keeps.
TEST(MatchFinish, RefinedPassScoreIsTheLeastScoreThatPasses) {
  for (const float threshold : {0.1f, 33.3f, 50.f, 80.f, 80.5f, 87.3f, 90.f, 99.9f, 100.f})
    for (int n = 1; n <= 300; ++n) {
      const int pass = match::refinedPassScore(n, threshold);
      for (int s = 0; s <= 4 * n; ++s)
        ASSERT_EQ(s >= pass, match::similarityPercent(s, n) >= threshold)
            << n << " features, score " << s << ", threshold " << threshold;
    }
}

std::vector<Match> plainWay(std::vector<Match> matches) {
  sortMatches(matches);
  matches.erase(std::unique(matches.begin(), matches.end(),
                            [](const Match& a, const Match& b) {
                              return a.template_id == b.template_id && a.x == b.x && a.y == b.y;
                            }),
                matches.end());
  return matches;
}

// Repeats (one template's candidates refined to the same position) come out once, best first,
// as sorting and std::unique would leave them: with many equal similarities, negative
// positions, and coordinates too far apart for the packed keys (the plain way then).
TEST(MatchFinish, DistinctMatchesComeOutAsSortingAndUniqueWouldLeaveThem) {
  std::mt19937 rng(5);
  for (const int spread : {1, 40, 700, INT_MAX / 4}) {
    std::vector<Match> matches;
    std::uniform_int_distribution<int> position(-spread / 2, spread / 2), templ(0, 3000);
    for (int i = 0; i < 20000; ++i) {
      Match m;
      m.template_id = templ(rng);
      m.x = position(rng);
      m.y = position(rng);
      m.raw_score = 100 + (m.template_id * 7 + m.x * 3 + m.y) % 50;  // a function of template and place
      m.similarity = static_cast<float>(m.raw_score) / 2.f;
      matches.push_back(m);
      if (i % 3 == 0) matches.push_back(m);  // a repeat
    }
    std::shuffle(matches.begin(), matches.end(), rng);
    const std::vector<Match> expected = plainWay(matches);
    match::sortDistinctMatches(matches);
    EXPECT_EQ(matches.size(), expected.size()) << "spread " << spread;
    EXPECT_EQ(matches, expected) << "spread " << spread;
  }
  std::vector<Match> none;
  match::sortDistinctMatches(none);
  EXPECT_TRUE(none.empty());
  std::vector<Match> one(1);
  match::sortDistinctMatches(one);
  EXPECT_EQ(one.size(), 1u);
}

}  // namespace
}  // namespace vkpose
