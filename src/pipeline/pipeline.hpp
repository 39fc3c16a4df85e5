#pragma once
// Helpers of the per-frame flow that tests and the baselines share.
#include "hypotheses/cluster_score.hpp"
#include "match/matcher.hpp"
#include "vkpose/detector.hpp"

namespace vkpose {

/// Checks a frame and its camera for detection and returns the camera with the frame's size
/// (scene_camera.json entries carry none). Throws InputError for a bad frame (validateFrame), a
/// bad camera, or a principal point outside the frame (intrinsics of another camera).
Camera frameCamera(const LinemodFrame& frame, const Camera& camera, const FeatureParams& features);

/// The pose a hypothesis's template implies: the template's rotation turned onto the viewing
/// ray through the hypothesis centre, at the template's distance moved by the member's mean
/// depth offset.
Pose templatePose(const Hypothesis& h, const MemberScore& s, const BankTemplate& t, const TemplateBank& bank,
                  const Camera& camera);

/// Stages 1-2's times under the names the detection JSON reports them by: "upload" (when the
/// templates were uploaded), "features", "similarity", "match_readback", and the GPU's share
/// of the first two in kernel_ms.
void appendMatchTimings(const MatchTimings& timings, DetectionResult& to);

}  // namespace vkpose
