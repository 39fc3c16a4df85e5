#pragma once
// What the detector finds: a Detection per object instance (its pose and the evidence for it),
// a DetectionResult per frame (detections, rejected hypotheses, stage times). Plain data: the
// pose stages (src/pose/) fill them, the detection JSON (docs/formats.md) writes them.
#include <cstddef>
#include <cstdint>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "vkpose/geometry.hpp"

namespace vkpose {

/// A pose that one of the object's near-symmetries offers (NearSymmetry), rendered and
/// compared with the scene (VerifyParams::resolve_symmetries).
struct SymmetryAlternative {
  float angle_deg = 0.f;                            ///< 0: ICP's own pose
  Eigen::Vector3f axis = Eigen::Vector3f::UnitZ();  ///< object frame
  float depth_fit = 0.f;  ///< share of the visible rendered pixels within tolerance of the scene's depth
  float colour = 0.f;     ///< agreement of rendered and seen chromaticity (appearance.hpp), -1..1 (0 without colour)
  float score = 0.f;      ///< depth_fit * (1 + colour) / 2 with colour, else depth_fit
  /// Mean distance of the visible rendered pixels' depth from the scene's, each capped at
  /// the tolerance (metres; look-alike turns only, where it is part of the score).
  float depth_residual_m = 0.f;
};

/// One detected object instance.
struct Detection {
  int bank = 0;
  std::string object;         ///< the bank's object name
  /// gamma without stages 6-8; with them the verification score
  /// phi * (1 - see-through share) * silhouette support
  float score = 0.f;
  float gamma = 0.f;          ///< cluster score alpha * beta
  float alpha = 0.f, beta = 0.f;
  float x = 0.f, y = 0.f;     ///< image position of the object's centre
  cv::Rect2f bbox;            ///< pixels: the best template's object box
  Pose pose;                  ///< refined pose (or, without stages 6-8, the best template's)
  int templates = 0;          ///< members of the cluster
  int template_index = -1;    ///< the best template (within the bank)
  float similarity = 0.f;     ///< its LINEMOD similarity, percent
  // Stages 6-8; unset (verified false, collision_rate -1) when they did not run.
  bool verified = false;       ///< the refined pose passed verification
  float collision_rate = -1.f; ///< phi
  float see_through = 0.f;     ///< share of the visible model points the camera sees through
  float depth_fit = 0.f;       ///< share of the visible model points within tolerance of the scene depth
  float silhouette_support = 0.f;  ///< share of the outline with a depth step behind it
  float contour_edges = 0.f;       ///< share of the visible outline that meets an image edge along it
  /// Share of the visible outline whose nearest image edge lies within 1.5 px of it (a right
  /// pose's outline sits on the object's edges; a look-alike's strays where the shapes differ).
  /// Picking asks for PickParams::min_outline_on_edges. NaN where not measured.
  float outline_on_edges = std::numeric_limits<float>::quiet_NaN();
  /// How large the scene's silhouette around the pose's outline is, x the model's (depth steps
  /// found along the outline's normals, fitted as a scaling about its centre): about 1 for the
  /// part, 1.1-1.2 for a model fitted into a larger look-alike. NaN where not measured.
  float silhouette_scale = std::numeric_limits<float>::quiet_NaN();
  /// Agreement (-1..1) of the rendered mesh's chromaticity with the frame's over the pixels
  /// where the pose fits the depth (appearanceAgreement): a correlation where the rendering
  /// shows several colours, a match of the colour itself where it shows one; 1 when not
  /// measured (a mesh without vertex colours, or the test turned off).
  float colour_agreement = 1.f;
  /// colour_agreement was measured (the mesh has colours, the rendering shows enough of them
  /// and the test is on); picking leans less on the outline of a pose whose colour passed.
  bool colour_measured = false;
  /// Posed without depth (colour-only frames): the pose was fitted to the image's edges,
  /// `contour_edges` and `colour_agreement` verified it, and no depth test ran.
  bool colour_only = false;
  /// Colour only: of the frame's edge pixels under the pose's mask, the share that the model's
  /// own edges (outline, colour edges) explain; a pose laid on clutter covers edges it cannot.
  float explained_edges = 0.f;
  /// Colour only, a mesh without colours over a surface of one colour: the share of its outline
  /// alone (silhouette and depth steps, not the shading's edges) that meets an image edge, the
  /// test such a pose passes instead of `contour_edges` (ColourOnlyParams::min_plain_outline_support).
  /// It gates only; the score keeps `contour_edges`. NaN where not measured.
  float plain_outline_edges = std::numeric_limits<float>::quiet_NaN();
  /// Colour only: how well the frame's colours tell the pose's mask from a band around it
  /// (0..1: 0 the same colours on both sides); the score is multiplied by a power of it
  /// (ColourOnlyParams::region_contrast_power). NaN where not measured.
  float region_contrast = std::numeric_limits<float>::quiet_NaN();
  double icp_fitness = 0;      ///< mean squared pair distance after ICP, m^2
  int icp_iterations = 0;
  int rotation_votes = 0;      ///< templates in the largest rotation group
  std::string rejection;       ///< why a hypothesis was rejected (empty when accepted)
  /// The near-symmetric poses compared (ICP's first; empty when the object has none or the
  /// check did not run), the one kept, and by how much it beat the best other. Ambiguous:
  /// the margin is below VerifyParams::symmetry_margin (an uncoloured mesh cannot tell).
  std::vector<SymmetryAlternative> symmetry_alternatives;
  int symmetry_chosen = 0;
  float symmetry_margin = 0.f;
  bool ambiguous_symmetry = false;
  /// false: the mesh has no colours, so the alternatives were listed (angle and axis; scores
  /// 0) but not rendered, and the pose is ambiguous.
  bool symmetry_compared = true;
  /// Look-alike half-turns (VerifyParams::look_alike_tolerance) refit by ICP and compared,
  /// the kept pose first (angle 0); score = depth_fit * (1 - residual / tolerance), times
  /// (1 + colour) / 2 with colour. Chosen: the index kept; margin: by how much it beat the
  /// best other. Empty when the object has none or the pose was not accepted so far.
  std::vector<SymmetryAlternative> look_alike_alternatives;
  int look_alike_chosen = 0;
  float look_alike_margin = 0.f;
};

/// The stages a DetectionResult times, in pipeline order. Colour-only frames time `edges` and
/// `contour_fit` in place of `first_fit`, `mls` and `icp`; the linemod baseline times `poses`.
enum class Stage {
  upload, depth_pruning, features, similarity, match_readback,  // stages 1-2
  clustering, scoring, nms,                                      // stages 3-5
  initial_pose, first_fit, mls, icp, verification, symmetries,   // stages 6-8
  edges, contour_fit, poses, total
};
/// What the detection JSON, Python and the benchmarks call a stage.
constexpr const char* stageName(Stage stage) {
  constexpr const char* kNames[] = {"upload",       "depth_pruning", "features", "similarity",   "match_readback",
                                    "clustering",   "scoring",       "nms",      "initial_pose", "first_fit",
                                    "mls",          "icp",           "verification", "symmetries", "edges",
                                    "contour_fit",  "poses",         "total"};
  return kNames[static_cast<int>(stage)];
}

/// Milliseconds per stage, in pipeline order, under stageName().
using StageTimings = std::vector<std::pair<std::string, double>>;
/// Adds a stage's milliseconds under its name.
inline void addStage(StageTimings& timings, Stage stage, double ms) { timings.emplace_back(stageName(stage), ms); }

struct DetectionResult {
  std::vector<Detection> detections;  ///< best score first
  std::vector<Detection> rejected;    ///< hypotheses that stages 6-8 rejected, with the reason
  StageTimings timings_ms;
  /// The GPU's own time within each stage of timings_ms that the detector times itself (device
  /// timestamps of the submits it waited for; 0 where the queue writes none): a stage's
  /// timings_ms less this is host work (recording, submitting, waiting, reading back, the CPU).
  StageTimings kernel_ms;
  std::size_t matches = 0, hypotheses = 0, scored_hypotheses = 0;  ///< counts after stages 2, 3, 4
  /// Stage 2's depth-guided pruning (MatchParams::depth_pruning): (template, position) pairs
  /// of the coarse pass, those whose scene depth does not suit the template's distance, and
  /// those of them in strips the GPU skipped whole (no memory read). 0 without pruning.
  uint64_t match_pairs = 0, match_pairs_pruned = 0, match_pairs_skipped = 0;
  /// Stages 7-8's budget: pose candidates that were refined and verified (stage 6 found scene
  /// depth under them and the first fit did not stop them), and the CPU time of stages 7-8 of
  /// every candidate stage 6 placed (first fit, MLS, ICP and verification, each candidate timed
  /// on its own thread: the cost on one core, whatever the thread count).
  std::size_t refined_candidates = 0;
  double refine_cpu_ms = 0;
  /// Stages 6-8 as a whole: their wall time, the CPU time the process spent meanwhile (all
  /// threads, the Vulkan driver's too), and the threads their candidates ran on
  /// (DetectorParams::threads, at most one a candidate). On N threads the wall time is about
  /// 1/N of the CPU time when the pose stages keep every thread busy.
  double pose_wall_ms = 0, pose_cpu_ms = 0;
  unsigned pose_threads = 0;
  std::vector<std::string> warnings;  ///< e.g. a bank trained for another focal length
};

}  // namespace vkpose
