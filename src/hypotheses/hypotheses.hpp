#pragma once
// Stages 3 and 5 (docs/pipeline.md): LINEMOD's many overlapping matches become one hypothesis per
// object instance. Clustering groups matches that put the same object's centre in the same
// image cell at the same training distance; non-maximum suppression keeps, among hypotheses
// that sit on one instance, the one with the best cluster score (stage 4, cluster_score.hpp).
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "match/matcher.hpp"
#include "vkpose/bank.hpp"
#include "vkpose/config.hpp"

namespace vkpose {

/// Global template ids of several banks' templates concatenated in bank order (the order
/// one LinemodMatcher sees them in): bank b's template i has id first[b] + i.
struct TemplateIndex {
  std::vector<int> first;  ///< one per bank, plus the total at the end

  explicit TemplateIndex(const std::vector<TemplateBank>& banks);
  int bankOf(int global_id) const;
  int localId(int global_id) const { return global_id - first[static_cast<std::size_t>(bankOf(global_id))]; }
};

/// The LINEMOD templates of all banks, concatenated as TemplateIndex numbers them.
std::vector<LinemodTemplate> concatenateTemplates(const std::vector<TemplateBank>& banks);

/// One template of a hypothesis: the best of its matches in the cluster.
struct ClusterMember {
  int template_index = 0;    ///< within the hypothesis's bank
  int x = 0, y = 0;          ///< the match: template top-left, level-0 pixels
  float similarity = 0.f;    ///< percent
  float centre_x = 0.f, centre_y = 0.f;  ///< where this match puts the object's centre (pixels)
};

/// Per-member result of the cluster score (stage 4).
struct MemberScore {
  int object_cells = 0;        ///< cells of the template crop that show the object
  int depth_pairs = 0;         ///< ... of those with a scene depth
  int normal_pairs = 0;        ///< ... of those with a scene normal too
  float depth_offset = 0.f;    ///< mean scene - template depth over the pairs, metres
  float depth_error = 0.f;     ///< mean |difference - offset|, truncated, metres
  float angle_error = 0.f;     ///< mean angle between template and scene normals, radians

  /// The member's own alpha * beta: how well its template alone fits the scene's depth and
  /// normals (stage 4 ranks members by it; stage 6 weighs their rotation votes by it).
  float fit(const ScoreParams& params) const;
};

/// One object instance candidate.
struct Hypothesis {
  int bank = 0;                 ///< index into the banks (the object)
  float x = 0.f, y = 0.f;       ///< image position of the object's centre: mean over members
  float distance = 0.f;         ///< training distance of the members, metres
  std::vector<ClusterMember> members;  ///< best similarity first
  // Stage 4: filled by the cluster score.
  std::vector<MemberScore> member_scores;  ///< one per member
  float alpha = 0.f, beta = 0.f;  ///< depth and normal agreement, 0..1
  float score = 0.f;              ///< gamma = alpha * beta
  int best_member = -1;           ///< the member whose template agrees best with the scene
};

/// Stage 3: groups the matches (global template ids, see TemplateIndex) by bank, by the
/// s_im cell of the object centre they imply and by training distance; a group with fewer
/// than tau_c distinct templates is dropped. Hypotheses come out in a deterministic order
/// (bank, then cell, then distance).
std::vector<Hypothesis> clusterTemplates(const std::vector<Match>& matches, const std::vector<TemplateBank>& banks,
                                         const ClusterParams& params = {});

/// What stage 5 ranks by: gamma; for a part smaller than kSmallPartDiameterM, times the
/// cluster's template count to the power `template_weight`.
float nmsRank(const Hypothesis& h, const std::vector<TemplateBank>& banks, const NmsParams& params);

/// Stage 5: hypotheses sorted by nmsRank (best first), then each survives unless a better
/// survivor's centre lies within the radius (centres stay where they are; nothing merges).
/// `fx` turns the banks' diameters at the hypotheses' distances into pixels.
std::vector<Hypothesis> suppressNonMaxima(std::vector<Hypothesis> hypotheses, const std::vector<TemplateBank>& banks,
                                          double fx, const NmsParams& params = {});

/// The object's projected diameter in pixels at the hypothesis's distance.
float projectedDiameter(const Hypothesis& h, const std::vector<TemplateBank>& banks, double fx);

/// The image box of a template's object crop placed at the hypothesis centre (pixels).
cv::Rect2f templateBox(const Hypothesis& h, const BankTemplate& t);

/// The rotation that turns the optical axis onto the viewing ray through pixel (x, y): a
/// template rendered on the axis appears at (x, y) as if the object were rotated by it (up to
/// about 30 degrees at a Kinect image's corners).
Eigen::Matrix3f viewingRayRotation(float x, float y, const Camera& camera);

/// Stage 5's runners-up (NmsParams::runner_up_share): for each of `kept` (suppressNonMaxima's
/// survivors, best first, of objects of 10 cm and more) the best hypothesis of `all` (those
/// NMS ran on) that it suppressed, where that one's gamma is at least runner_up_share of the
/// survivor's and its best view is turned more than 30 degrees from the survivor's; for a bank
/// of several resting poses, one such hypothesis per resting pose of its best view, those of
/// another resting pose than the survivor's at resting_pose_runner_up_share. In the
/// survivors' order; empty when runner_up_share is 0.
std::vector<Hypothesis> runnersUp(const std::vector<Hypothesis>& all, const std::vector<Hypothesis>& kept,
                                  const std::vector<TemplateBank>& banks, double fx, const NmsParams& params);

/// Stage 5 as the detector runs it (DetectorParams): with poses, NMS within each object, the
/// best pose_candidates_per_object (small_part_pose_candidates) of each, and their runners-up;
/// without, one hypothesis a place for all objects.
std::vector<Hypothesis> nonMaximumSuppression(std::vector<Hypothesis> hypotheses, const std::vector<TemplateBank>& banks,
                                              float fx, const DetectorParams& params);

}  // namespace vkpose
