#pragma once
// Stage 8's acceptance rules (docs/pipeline.md, stage 8): which verified candidates become
// detections, each rule a named parameter of VerifyParams, and the competition between poses
// that claim one place or one piece of the scene.
#include <string>
#include <vector>

#include "pose/candidate.hpp"
#include "vkpose/bank.hpp"
#include "vkpose/config.hpp"
#include "vkpose/detection.hpp"

namespace vkpose {

/// Whether two poses put their objects' centres (the banks' centres) closer than
/// duplicate_fraction of the smaller diameter: one place, for stage 8's duplicates and for the
/// first fit's rounds.
bool samePlace(const Pose& a, std::size_t bank_a, const Pose& b, std::size_t bank_b,
               const std::vector<TemplateBank>& banks, float duplicate_fraction);

/// Whether two poses of one object are one pose: their centres within distance_fraction of
/// the diameter and their rotations within angle_deg (stage 8's twins, and the first fit's).
bool samePose(const Pose& a, const Pose& b, const TemplateBank& bank, float distance_fraction, float angle_deg);

/// A verified pose's score: the collision rate, times the share not seen through, times the
/// outline's support (Detection::score).
float poseScore(float collision_rate, float see_through, float silhouette_support);
float poseScore(const PoseEvidence& evidence);

/// The collision rate stage 8 tests: counted over the model points the scene does not hide,
/// with at most VerifyParams::occlusion_credit of them hidden.
float unhiddenCollisionRate(const PoseEvidence& evidence, const VerifyParams& params);

/// Passed the collision test: the candidate that the later checks (alternatives) consider.
bool collides(const PoseCandidate& c);

/// Hopeless: a pose whose outline shows under VerifyParams::hopeless_support_share of the
/// depth step the silhouette test asks for; its renderings and refits are spared.
bool hopeless(const PoseCandidate& c);

/// Twins: candidates that ICP brought within twin_distance_fraction of the diameter and
/// twin_angle_deg of a better one's pose (by poseScore) of the same object. A small part's
/// 64 candidates x 4 starts converge on a few instances; marking them before the alternatives
/// spares each its renderings and refits.
void markTwins(std::vector<PoseCandidate>& candidates, const std::vector<TemplateBank>& banks,
               const VerifyParams& params);

/// The first of stage 8's tests of the measured pose that a candidate fails (the collision
/// rate, the share seen through, the outline's depth steps and image edges), or empty. The
/// rounds of refinement (nextRound) ask it; rejectionReason adds the twin and colour rules.
std::string stageEightShortfall(const PoseCandidate& c);

/// Why a verified candidate is rejected, in the order the rules are tried; empty when accepted.
std::string rejectionReason(const PoseCandidate& c, const std::string& object);

/// Stage 8's duplicate test among one object's own verified poses: of two whose centres lie
/// closer than duplicate_fraction of the diameter, the one with the higher score times the
/// dense fit of its chosen look-alike alternative (where that check ran) stays; the other gets
/// the rejection "the same place as a better OBJECT detection". Poses of different objects
/// are left to the caller (ranked by the score alone: only some objects have that fit).
void rejectSameObjectDuplicates(std::vector<Detection>& verified, const std::vector<TemplateBank>& banks,
                                float duplicate_fraction);

/// The end of stage 8: each candidate becomes a Detection (its refined pose, evidence, score,
/// image box) that is accepted or rejected with the reason; then two poses in one place keep
/// the better (rejectSameObjectDuplicates, then across objects by score), and objects compete
/// for the scene, best first: a detection whose explained cells are mostly claimed by better
/// ones (VerifyParams::max_shared_support) goes. Appends to result.detections (best first)
/// and result.rejected.
void acceptPoses(std::vector<PoseCandidate>& candidates, const std::vector<TemplateBank>& banks,
                 const Camera& camera, const DetectorParams& params, DetectionResult& result);

}  // namespace vkpose
