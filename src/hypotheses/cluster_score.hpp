#pragma once
// Stage 4 (docs/pipeline.md): the cluster score gamma = alpha * beta. Each template of a hypothesis
// is laid on the scene at the hypothesis's centre; its stored depth and normal crop is
// compared with the scene's depth and normals over the cells where both are valid:
//   alpha = exp(-mean |depth difference - mean depth difference| / depth_unit)
//   beta  = exp(-mean normal angle / angle_unit)
// The mean depth difference is taken out first: the template was rendered at its training
// distance, the instance sits somewhere between two training radii, and the score is about
// shape, not about which radius.
//
// Choices, measured on synthetic cup scenes with milk-jug and carton clutter and Kinect-like
// noise (8 scenes, 48 visible cups; docs/pipeline.md, stage 4):
// - Units: the paper's metres made alpha about 0.99 for everything (a few millimetres of
//   error is exp(-0.003)). Here depth errors are in centimetres (depth_unit_m = 0.01) and
//   angles in half radians, so a template that fits within 3 mm and 15 degrees scores about
//   0.4 and one that misses by 8 mm and 35 degrees about 0.13. Only the ratio of the two units changes the
//   ranking; 1 cm : 0.5 rad ranked best.
// - Pooling: alpha and beta come from the cluster's best-fitting members (top_members = 3).
//   Pooling every member, as the paper, lets the many loosely matching templates of a cluster
//   drown the few that fit: it kept 11-14 false positives where the best three kept 6.
#include <memory>
#include <vector>

#include <opencv2/core.hpp>

#include "hypotheses/hypotheses.hpp"
#include "vkpose/config.hpp"
#include "vkpose/device.hpp"
#include "vkpose/geometry.hpp"

namespace vkpose {

/// The scene as the cluster score sees it.
struct ScoreScene {
  cv::Mat depth_m;  ///< CV_32FC1, metres, 0 = no depth
  Camera camera;
};
ScoreScene makeScoreScene(const cv::Mat& depth_mm, const Camera& camera);

/// Stage 4 on the CPU: fills member_scores of the first max_members members of every
/// hypothesis (the reference the GPU kernel is tested against). Does not combine them.
void scoreMembersReference(std::vector<Hypothesis>& hypotheses, const std::vector<TemplateBank>& banks,
                           const ScoreScene& scene, const ScoreParams& params = {});

/// Combines each hypothesis's member scores into alpha, beta, gamma and the best member (the
/// one whose own alpha * beta is highest): alpha and beta average the errors of the
/// top_members best-fitting members. Members without enough evidence do not count.
void combineMemberScores(std::vector<Hypothesis>& hypotheses, const ScoreParams& params = {});

namespace gpu {
class ClusterScoreKernels;
}

/// Stage 4 on the GPU: one submit scores every member of every hypothesis
/// (shaders/cluster_score.comp), then combineMemberScores.
///
/// The banks' depth and normal crops go up once and stay on the device while the same banks
/// come back (the same TemplateBank objects, unchanged: a Detector's): a frame of many
/// objects scores some 40,000 templates, 200 MB of crops, which cost more to gather and
/// upload every frame than to score. Banks whose crops exceed `resident_crop_bytes` (or one
/// texel-buffer binding) have the crops of each frame's members uploaded with it instead.
class ClusterScorer {
 public:
  static constexpr std::size_t kResidentCropBytes = std::size_t(1) << 30;
  explicit ClusterScorer(const GpuContext& ctx, std::size_t resident_crop_bytes = kResidentCropBytes);
  ~ClusterScorer();
  ClusterScorer(const ClusterScorer&) = delete;
  ClusterScorer& operator=(const ClusterScorer&) = delete;

  /// Fills member_scores like scoreMembersReference, then combines them.
  void score(std::vector<Hypothesis>& hypotheses, const std::vector<TemplateBank>& banks, const ScoreScene& scene,
             const ScoreParams& params = {});
  /// Only the member scores (for the parity test).
  void scoreMembers(std::vector<Hypothesis>& hypotheses, const std::vector<TemplateBank>& banks,
                    const ScoreScene& scene, const ScoreParams& params = {});

 private:
  std::unique_ptr<gpu::ClusterScoreKernels> gpu_;
};

}  // namespace vkpose
