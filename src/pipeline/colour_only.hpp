#pragma once
// Frames without depth (docs/pipeline.md, colour only): what the Detector keeps for them, and
// the steps that differ from the RGB-D path, as plain functions.
#include <memory>
#include <vector>

#include "hypotheses/hypotheses.hpp"
#include "match/matcher.hpp"
#include "pose/candidate.hpp"
#include "pose/contour_fit.hpp"
#include "vkpose/detector.hpp"

namespace vkpose {

struct Detector::ColourOnlyStages {
  std::unique_ptr<LinemodMatcher> matcher;
  /// The colour matcher's template ids to the global ones (TemplateIndex): templates with no
  /// colour feature at some level are left out of it.
  std::vector<int> global_ids;
};

/// The banks' templates with their depth features dropped, and for each the global template
/// id it came from. Throws InputError when a bank has no colour modality.
std::vector<LinemodTemplate> colourTemplates(const std::vector<TemplateBank>& banks, std::vector<int>& global_ids);

/// Stage 4 without depth: each hypothesis scored by the mean similarity (0..1) of its best
/// three members, its best member the best match; member scores left empty of depth.
void scoreBySimilarity(std::vector<Hypothesis>& hypotheses);

/// Stages 7-8 without depth for each candidate: rounds of rendering, outline extraction and
/// the directional chamfer fit (contour_fit.hpp), then the outline's support and the colour
/// agreement at the final pose. Fills detection (pose, score, contour_edges, explained_edges,
/// plain_outline_edges, colour_agreement, verified, rejection). `camera`: the frame's; `bgr`: its colour image.
void fitAndVerifyByContour(std::vector<PoseCandidate>& candidates, const std::vector<PoseObject>& objects,
                           const Camera& camera, const cv::Mat& bgr, const EdgeDistanceMaps& maps,
                           const DetectorParams& params, const ContourFitParams& fit_params = {});

/// Where a fitted pose is fitted again from: its object's look-alike turns
/// (ColourOnlyParams::try_turns: the bank's near-symmetries where the mesh's colours tell them
/// apart, and the look-alike half-turns; none for a symmetric bank), then the pose tilted by
/// tilt_restart_deg both ways about the camera's x and y axes through the object's centre.
std::vector<Pose> colourOnlyRestarts(const Pose& pose, const PoseObject& object, const ColourOnlyParams& cp);

/// The turns the colours choose among for a colourful object (ColourOnlyParams::colour_turns),
/// in the model's frame: the 23 turns of a cube (its axes permuted, signs that keep a rotation;
/// not the identity), then the eighth turns (45, 135, 225 and 315 degrees) about x, y and z.
std::vector<Eigen::Matrix3f> colourTurns();

/// Each candidate (one a hypothesis, fitted and verified) whose outline passed, fitted again
/// from its restarts (the finer rounds: 10, 5 and 3 px) and verified; the best scored of each
/// is kept, the others that passed go to `result.rejected`; the refits count in
/// `result.refined_candidates` and `refine_cpu_ms`. A turn fits the outline as well as
/// the pose, so the colours and inner edges choose; a tilt lets the fit leave a start 15-30
/// degrees off out of the image plane, where the outline fit turns little. Colourful objects
/// also start from the colour_turns best of colourTurns() after one screening round. Up to
/// ColourOnlyParams::restart_rounds rounds: after the first, the poses a restart improved
/// start again from their own look-alike turns and tilts (a colour turn that found the right
/// face, then a tilt that squares it up).
void refitFromRestarts(std::vector<PoseCandidate>& candidates, const std::vector<PoseObject>& objects,
                       const Camera& camera, const cv::Mat& bgr, const EdgeDistanceMaps& maps,
                       const DetectorParams& params, DetectionResult& result);

}  // namespace vkpose
