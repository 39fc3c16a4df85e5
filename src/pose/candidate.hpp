#pragma once
// Stages 6-8 over one frame (docs/pipeline.md): a pose candidate is one rotation start of a
// hypothesis, and each stage is a function that fills in its part of every candidate:
//   startCandidates    stage 6, rotations: each hypothesis's starts, posed on its viewing ray
//   initialPoses       stage 6, translations: each start rendered and moved onto the scene
//   firstFits          stage 7, a cheap first fit of every start (ICP on the raw crop)
//   screenStarts       stage 7, the starts whose first fit shows they cannot pass stage 8 stop
//   nextRound          stage 7, the starts refined next: another object's better one first
//   smoothSceneCrops   stage 7, MLS of each of a round's scene crops
//   refineCandidates   stage 7, ICP
//   verifyCandidates   stage 8, the evidence: collision rate, depth agreement, outline tests
// then alternatives.hpp (near-symmetries, look-alikes) and accept.hpp (the acceptance rules and
// the competition between poses). Candidates are independent: each function runs them on
// `threads` threads with results identical to one thread.
#include <cstddef>
#include <limits>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "hypotheses/hypotheses.hpp"
#include "pose/initial_pose.hpp"
#include "geometry/point_cloud.hpp"
#include "pose/refine.hpp"
#include "pose/verify.hpp"
#include "vkpose/bank.hpp"
#include "vkpose/config.hpp"
#include "vkpose/detection.hpp"
#include "vkpose/geometry.hpp"

namespace vkpose {

class MeshRenderer;

/// What stages 6-8 know of one object (one bank).
struct PoseObject {
  const TemplateBank* bank = nullptr;
  MeshRenderer* renderer = nullptr;  ///< renders the object for stage 6 and the alternatives (GPU)
  float bounding_radius = 0.f;       ///< farthest mesh vertex from bank->centre, metres
  /// Its colours vary enough to tell near-symmetric turns apart (kMinChromaSpread).
  bool colourful = false;
  /// Look-alike half-turns (findLookAlikeTurns; empty for symmetric objects).
  std::vector<NearSymmetry> look_alike_turns;
};

/// Each bank's PoseObject, but its renderer (the Detector attaches those): its bounding
/// radius, whether its colours vary, and (verify.resolve_symmetries) its look-alike turns,
/// about 0.1 s a mesh, so found here rather than stored in the bank.
std::vector<PoseObject> poseObjects(const std::vector<TemplateBank>& banks, const DetectorParams& params);

/// What stages 6-8 read of one frame.
struct PoseFrame {
  Camera camera;      ///< with the frame's size
  cv::Mat depth_m;    ///< CV_32FC1 metres, 0 = none
  cv::Mat bgr;        ///< CV_8UC3 of depth_m's size; black when the frame has no colour
  ImageEdges edges;   ///< of bgr, for the contour test
};

/// The frame as stages 6-8 read it: a colour image that is missing or of another size than the
/// depth is replaced by black (the tests then compare depth alone).
PoseFrame poseFrame(const Camera& camera, const cv::Mat& depth_m, const cv::Mat& bgr);

/// Stage 8's measurements of a refined pose (verify.hpp has each test).
struct PoseEvidence {
  VerifyResult collision;       ///< the octree collision rate phi
  DepthAgreement depth;         ///< seen-through and fitting shares of the visible model
  float silhouette_support = 0.f;
  float contour_edges = 0.f;
  std::vector<int> explained;   ///< the scene cells it explains (supportCells)
  /// The better outline support (outlineSupport) of the model scaled by 1/1.15 and 1.15 about
  /// its centre (measured with the scene cells only): a look-alike of another size is
  /// explained better by another scale.
  float scaled_outline_support = 0.f;
  float outline_on_edges = 0.f;  ///< outlineOnEdges: how closely the outline lies on the image's edges
  /// silhouetteScale: the scene's silhouette around the outline, times the model's (stage 8 only:
  /// no first-fit test reads it; NaN where not measured).
  float silhouette_scale = std::numeric_limits<float>::quiet_NaN();
  /// The outline's support at the part's own size: contour edges and silhouette, averaged.
  float outlineSupport() const { return outlineSupport(contour_edges, silhouette_support); }
  /// The same average of any outline's two shares (the size probe's scaled models).
  static float outlineSupport(float contour_edges, float silhouette_support) {
    return 0.5f * (contour_edges + silhouette_support);
  }
};

/// One start of stages 6-8 and what each stage found for it.
struct PoseCandidate {
  /// What stages 1-5 know of its hypothesis (hypothesisDetection); acceptPoses fills in the rest.
  Detection detection;
  Pose start;              ///< stage 6's rotation start on the viewing ray: where it renders
  InitialPose initial;     ///< stage 6: the start moved onto the scene, its model and scene points
  RefineParams refine;     ///< stages 7-8's parameters for its object at its distance (scaledForObject)
  VerifyParams verify;
  PointCloud smoothed;     ///< stage 7: the scene crop after MLS
  RefineResult refined;    ///< stage 7: ICP's pose
  PoseEvidence evidence;   ///< stage 8
  RefineResult first_fit;        ///< stage 7's first fit (firstFits)
  PoseEvidence first_evidence;   ///< stage 8's tests at the first fit (no scene cells)
  /// The chromaticity concordance of its first fit's rendering with the frame
  /// (firstFitColours); NaN where it was not measured or the colours said too little.
  float first_colour = std::numeric_limits<float>::quiet_NaN();
  /// The collision rate its first fit needs to go on (initialPoses; RefineParams::first_fit_share).
  float first_fit_min_collision = 0.f;
  /// Why the first fit stopped it (screenStarts, nextRound); empty: it goes on to MLS and ICP.
  std::string screened;
  bool measured = false;   ///< stage 8 measured its refined pose (verifyCandidate)
  /// ICP brought it to the pose of a better candidate (markTwins): not compared or accepted.
  bool twin = false;
  double cpu_ms = 0;       ///< stages 7-8's CPU time for this candidate
  /// Colour only: its outline met as many image edges as verification asks
  /// (fitAndVerifyByContour); only those are fitted again from restarts.
  bool outline_passed = false;

  std::size_t bank() const { return static_cast<std::size_t>(detection.bank); }
  /// Stage 6 placed it and the first fit did not stop it: MLS, ICP and stage 8 run on it (or
  /// will, in a later round).
  bool refinable() const { return initial.ok && screened.empty(); }
};

/// What stages 1-5 know about a hypothesis: its score, image position, best template and box.
Detection hypothesisDetection(const Hypothesis& h, const std::vector<TemplateBank>& banks);

/// Stage 6, rotations: for each hypothesis its largest rotation group (initialRotation), and
/// for a small part (InitialPoseParams::small_part_starts) or a bank with other resting poses
/// (resting_poses_starts) the next largest, then the group that fits best by stage 4 where
/// that is another; each posed on the hypothesis's viewing ray (poseOnViewingRay).
std::vector<PoseCandidate> startCandidates(const std::vector<Hypothesis>& hypotheses,
                                           const std::vector<TemplateBank>& banks, const Camera& camera,
                                           const DetectorParams& params);

/// One hypothesis's starts: its largest rotation group, the next largest up to `starts` in all,
/// the group that fits best by stage 4 where that is another (initialRotation) and, with
/// `best_match_start`, the group of its best-matching template where that is another, each
/// posed on its viewing ray.
std::vector<PoseCandidate> hypothesisStarts(const Hypothesis& h, const std::vector<TemplateBank>& banks,
                                            const Camera& camera, const DetectorParams& params, int starts,
                                            bool best_match_start = false);

/// Stage 8's tests as `bank`'s object gets them: a part under 10 cm asks more of its colour
/// (small_part_min_colour_agreement), and one that is a body of revolution (trained
/// --symmetric, or revolutionAxis() in its near-symmetries) more of its outline on the image's
/// edges (small_turned_part_min_outline_on_edges); larger objects keep `verify`. The size test
/// (max_silhouette_scale) is for parts of 10 cm or more trained nearer than kPileDistanceM only.
VerifyParams partVerifyParams(VerifyParams verify, const TemplateBank& bank);

/// Stage 6, translations: each start rendered in its own window (projectedWindow: one small
/// submit each) and moved by the centroid difference (initialTranslation); then each
/// candidate's stage 7-8 parameters, scaled for its object at its distance, with the higher
/// collision rate a start moved along the camera's axis needs (second_try_min_collision).
void initialPoses(std::vector<PoseCandidate>& candidates, const std::vector<PoseObject>& objects,
                  const PoseFrame& frame, const DetectorParams& params);

/// Stage 7, first fit (RefineParams::first_fit): each placed candidate's two ICP stages with
/// the coarse stage's thinned model points on its unsmoothed crop, and stage 8's measurements
/// at that pose (first_evidence).
void firstFits(std::vector<PoseCandidate>& candidates, const PoseFrame& frame, unsigned threads);

/// Stage 7, after the first fit: stops (PoseCandidate::screened) each start whose first fit
/// falls short of a stage 8 limit by more than RefineParams::first_fit_share allows (the
/// image-edge support: first_fit_contour_share).
void screenStarts(std::vector<PoseCandidate>& candidates);

/// Stage 7, after screenStarts: each start still going whose mesh has colours and whose
/// colour test is on (verify.min_colour_agreement > -1) is rendered at its first fit (each
/// object's starts in one call, in the calling thread) and stops where its colours agree with the
/// frame's less than stage 8's limit minus RefineParams::first_fit_colour_margin: another
/// object of the right shape and the wrong colour, which MLS and ICP would not change.
void firstFitColours(std::vector<PoseCandidate>& candidates, const std::vector<PoseObject>& objects,
                     const PoseFrame& frame, unsigned threads);

/// Stage 7, the next round of refinement: the indices of the candidates that MLS, ICP and
/// stage 8 take next. Without the first fit, every placed one in one round. With it, ranked
/// by stage 8's score at the first fit, a start stops (screened) where a better start of its
/// object lies at the same pose (RefineParams::first_fit_twin_angle_deg), where
/// first_fit_per_place better starts of its object lie in its place (centres closer than
/// duplicate_fraction of the diameter) or where a better start of another object (the
/// smaller diameter's place) passed stage 8's tests (stageEightShortfall); it waits while such a start is not measured
/// yet, and goes otherwise. Empty when every placed candidate is measured or stopped. The
/// rounds depend on the measurements only, never on the threads.
std::vector<std::size_t> nextRound(std::vector<PoseCandidate>& candidates, const std::vector<TemplateBank>& banks,
                                   float duplicate_fraction);

/// Stage 7, first step: the round's candidates' scene crops smoothed by MLS (RefineParams::mls).
void smoothSceneCrops(std::vector<PoseCandidate>& candidates, const std::vector<std::size_t>& round,
                      unsigned threads);

/// Stage 7, second step: ICP of each of the round's model points onto its smoothed crop.
void refineCandidates(std::vector<PoseCandidate>& candidates, const std::vector<std::size_t>& round,
                      unsigned threads);

/// Stage 8's measurements of `model_points` (object frame) at `pose` against the scene; the
/// scene cells it explains (PoseEvidence::explained) and the size tests only with `with_cells`
/// (the first fits' screen reads neither).
PoseEvidence measurePose(const PointCloud& model_points, const Pose& pose, const PointCloud& scene_points,
                         const PoseFrame& frame, const VerifyParams& params, bool with_cells = true);

/// Stage 8: a refined candidate's evidence (measurePose at its refined pose), its time added
/// to cpu_ms.
void verifyCandidate(PoseCandidate& candidate, const PoseFrame& frame);

/// Stage 8: verifyCandidate for each of the round's candidates.
void verifyCandidates(std::vector<PoseCandidate>& candidates, const std::vector<std::size_t>& round,
                      const PoseFrame& frame, unsigned threads);

}  // namespace vkpose
