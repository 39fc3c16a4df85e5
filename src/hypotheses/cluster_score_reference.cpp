// Stage 4 on the CPU (the reference of shaders/cluster_score.comp) and the combination of
// member scores into gamma, which both paths share.
#include <cmath>
#include <string>

#include "hypotheses/cluster_score_math.hpp"
#include "vkpose/error.hpp"

namespace vkpose {

ScoreScene makeScoreScene(const cv::Mat& depth_mm, const Camera& camera) {
  if (depth_mm.empty() || depth_mm.type() != CV_16UC1)
    throw InputError("cluster score: the depth image must be 16-bit millimetres");
  validateCamera(camera);
  ScoreScene s;
  depth_mm.convertTo(s.depth_m, CV_32F, 1e-3);
  s.camera = camera;
  return s;
}

float MemberScore::fit(const ScoreParams& params) const {
  return std::exp(-depth_error / params.depth_unit_m) * std::exp(-angle_error / params.angle_unit_rad);
}

void scoreMembersReference(std::vector<Hypothesis>& hypotheses, const std::vector<TemplateBank>& banks,
                           const ScoreScene& scene, const ScoreParams& params) {
  validateScoreParams(params);
  for (auto& h : hypotheses) {
    const auto& bank = banks.at(static_cast<std::size_t>(h.bank));
    const Eigen::Matrix3f ray = viewingRayRotation(h.x, h.y, scene.camera);
    h.member_scores.assign(score::scoredMembers(h, params), {});
    for (std::size_t m = 0; m < h.member_scores.size(); ++m) {
      const BankTemplate& t = bank.templates.at(static_cast<std::size_t>(h.members[m].template_index));
      h.member_scores[m] = score::scoreMember(t, score::placeMember(h, t), ray, scene, params);
    }
  }
}

void combineMemberScores(std::vector<Hypothesis>& hypotheses, const ScoreParams& params) {
  struct Ranked {
    float own;
    std::size_t member;
  };
  for (auto& h : hypotheses) {
    std::vector<Ranked> ranked;
    for (std::size_t m = 0; m < h.member_scores.size(); ++m) {
      const MemberScore& s = h.member_scores[m];
      if (s.object_cells == 0 || s.normal_pairs == 0 ||
          static_cast<float>(s.depth_pairs) < params.min_valid_fraction * static_cast<float>(s.object_cells))
        continue;
      ranked.push_back({s.fit(params), m});
    }
    // Best fit first; ties by member order (best similarity first), so the result is stable.
    std::stable_sort(ranked.begin(), ranked.end(), [](const Ranked& a, const Ranked& b) { return a.own > b.own; });
    h.alpha = h.beta = h.score = 0.f;
    h.best_member = ranked.empty() ? -1 : static_cast<int>(ranked.front().member);
    if (ranked.empty()) continue;
    // alpha and beta pool the cells of the k best-fitting members; a cluster with fewer
    // scored members counts the missing ones as errors at the cap (no evidence is not a fit).
    const std::size_t k = static_cast<std::size_t>(std::max(1, params.top_members));
    double depth_sum = 0, angle_sum = 0;
    for (std::size_t i = 0; i < k; ++i) {
      if (i < ranked.size()) {
        const MemberScore& s = h.member_scores[ranked[i].member];
        depth_sum += s.depth_error;
        angle_sum += s.angle_error;
      } else {
        depth_sum += params.depth_cap_m;
        angle_sum += 0.5 * 3.14159265358979;
      }
    }
    h.alpha = static_cast<float>(std::exp(-depth_sum / static_cast<double>(k) / params.depth_unit_m));
    h.beta = static_cast<float>(std::exp(-angle_sum / static_cast<double>(k) / params.angle_unit_rad));
    h.score = h.alpha * h.beta;
  }
}

}  // namespace vkpose
