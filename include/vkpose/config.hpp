#pragma once
// The detector's parameters, one struct per stage with the paper's or the measured defaults and
// what each does, and the config file (`--config FILE`) that sets them: every DetectorParams
// field, grouped by stage, as JSON. `vkpose config --print-defaults` writes the defaults.
#include <cstddef>
#include <string>
#include <variant>
#include <vector>

namespace vkpose {

/// Objects smaller than this (metres across) are small parts: the pose stages' lengths follow
/// their size (kScaleReferenceDiameter), training covers every resting pose (`--resting
/// auto`), NMS ranks them by their templates too (NmsParams::template_weight) and stage 6
/// starts them from several rotations (InitialPoseParams::small_part_starts). Everything of
/// 10 cm and more (LM-O, IC-BIN, the demo, Tejani's objects) takes none of these paths.
inline constexpr float kSmallPartDiameterM = 0.1f;
/// Whether an object of this diameter (metres) is a small part (kSmallPartDiameterM).
inline constexpr bool isSmallPart(float diameter_m) { return diameter_m < kSmallPartDiameterM; }

// ---- stage parameters ------------------------------------------------------------------

struct MatchParams {
  /// Similarity in percent a match needs; 0 % is what a random image gives (half the maximum
  /// response per feature), 100 % a perfect match (OpenCV's convention).
  float threshold = 80.0f;
  /// Where the frame has depth, score a template only at positions whose scene depth suits
  /// its training distance (docs/pipeline.md, stage 2): the same matches that pass that test,
  /// for less work.
  bool depth_pruning = true;
  /// Response (0..4 of a feature's 4) that a template feature falling outside the image
  /// counts. OpenCV's 0 costs an object cut by the border the share of its features that
  /// lie outside, so its right views fall under the threshold while look-alike views of the
  /// part inside win. At 3 a position near the border passes only where its features inside
  /// the image match better than the threshold asks (3 of 4 is under the 3.6 that 80 % asks).
  int outside_response = 3;
  /// Parts under 10 cm, with a sensor whose depth of them is unreliable
  /// (SensorParams::small_parts_unreliable): each template is also matched on its colour
  /// features alone, and a position only that passes counts as the template's match
  /// (match/match_templates.hpp). A thin or shiny part whose depth the sensor merges into the
  /// background or leaves in holes fails the threshold on colour and depth together while its
  /// outline matches. Not with other sensors: on the bracket bins (Kinect-like depth) the
  /// extra matches are clutter (F1 0.95 -> 0.88).
  bool small_part_colour_alone = true;
};

struct ClusterParams {
  /// s_im: the object centres of matches are quantized into cells of this many pixels. The
  /// paper used about 12, and 12 ranked best here too (docs/pipeline.md, stage 3).
  int position_step_px = 12;
  /// tau_c: clusters of fewer distinct templates are noise (a lone template matching clutter).
  int min_templates = 3;
};

struct ScoreParams {
  float depth_unit_m = 0.01f;      ///< alpha's unit: alpha = exp(-error / unit)
  float depth_cap_m = 0.02f;       ///< per-cell depth errors are truncated here (occluders, background)
  float angle_unit_rad = 0.5f;     ///< beta's unit: beta = exp(-mean angle / unit)
  /// Scene normals: cross product of depth differences `normal_step_px` pixels either side;
  /// a difference larger than `normal_max_jump_m` is a depth edge (no normal there).
  int normal_step_px = 2;
  float normal_max_jump_m = 0.01f;
  /// A template must find scene depth on this share of its object cells, else it scores 0
  /// (no evidence: a hole in the depth map, or the template hangs over the image border).
  float min_valid_fraction = 0.5f;
  /// Members scored per hypothesis, best similarity first (0: all).
  int max_members = 32;
  /// alpha and beta pool this many best-fitting members (missing ones count as misfits).
  int top_members = 3;
};
/// Throws InputError naming the bad value.
void validateScoreParams(const ScoreParams& params);

struct NmsParams {
  /// r: a hypothesis is suppressed by a better one whose centre lies within this many
  /// pixels. 0: per pair, `radius_fraction` of the larger projected object diameter.
  float radius_px = 0.f;
  float radius_fraction = 0.5f;
  /// Suppress across objects too (one place in the image holds one object).
  bool across_objects = true;
  /// Parts smaller than 10 cm (kSmallPartDiameterM) are ranked by gamma * (templates in the
  /// cluster)^w instead of gamma alone. How many templates agree on a place is evidence the
  /// cluster score cannot see for parts a few LINEMOD cells across: their depth crops sit up to
  /// T pixels off, so a bare floor or a box's corner fits better than the part itself
  /// (docs/pipeline.md, stage 5). Larger objects keep gamma, which ranks them better. 0: gamma
  /// for every object.
  float template_weight = 1.f;
  /// Parts smaller than 10 cm (kSmallPartDiameterM), with stages 6-8: the suppression radius
  /// within the part's own hypotheses, a share of its projected diameter. A hypothesis is a
  /// cluster per 12-pixel cell and training distance, and on a part 30-60 pixels across the
  /// right view often sits in the cluster next to a look-alike one that ranks higher; half
  /// the diameter kept one per place. Verification's duplicate test removes the extra poses
  /// of one instance (small_part_pose_candidates gives room for them). Without stages 6-8
  /// (--no-pose) radius_fraction holds for every object.
  float small_part_radius_fraction = 0.1f;
  /// Objects of 10 cm and more, with stages 6-8: each survivor brings along the best
  /// hypothesis it suppressed whose gamma is at least this share of its own and whose best
  /// view is turned more than 30 degrees from the survivor's (runnersUp). A wrong view that
  /// fits a little better (a cluster on the edge of a box beside a lying cup, or a carton seen
  /// from its other side) otherwise hides the right one a cell away. A bank of several
  /// resting poses brings one per resting pose (a cup seen into its opening). 0: none.
  float runner_up_share = 0.5f;
  /// The share a runner-up of another resting pose than the survivor's needs instead. A cup
  /// seen straight into its opening scores low (its deep inside shifts against the rim
  /// between viewpoints) beside a view of its other end: 0.48 and 0.49 of that one's gamma on
  /// two bins. Lower than runner_up_share, since another resting pose is another side of the
  /// object, not a look-alike view of the same side.
  float resting_pose_runner_up_share = 0.4f;
};

struct InitialPoseParams {
  /// tau_theta: template rotations closer than this (axis-angle distance to a group's mean,
  /// degrees) vote for the same rotation (the paper: 10 degrees).
  float rotation_cluster_deg = 10.f;
  /// A second start per hypothesis: the rotation group whose members fit the scene's depth
  /// and normals best (stage 4's member scores, summed), where it is not the largest group.
  /// A cluster that mixes look-alike views (a jug lying on either flank, banks trained
  /// --resting all) holds groups of two or three templates, and the largest is often the
  /// wrong one. Both starts are refined and verified; the better survives.
  bool second_start_by_fit = true;
  /// Parts smaller than 10 cm (kSmallPartDiameterM): starts a hypothesis from this many of
  /// its largest rotation groups (and by_fit where that is none of them). A small part's
  /// cluster holds the views of all its resting poses, and on a bracket 30-60 pixels across
  /// the largest group is often a look-alike view (flat side for flat side); each start costs
  /// a few milliseconds there, and the best verified one survives. 1: the largest only.
  int small_part_starts = 4;
  /// Banks trained in several resting poses (`train --resting all`, bank.params.views.other_ups):
  /// starts a hypothesis from this many of its largest rotation groups, as small parts do. Their
  /// clusters mix look-alike views from several hemispheres (a milk jug lying on its flank
  /// matched end for end, or turned 57 degrees about its long axis, in the largest groups), and
  /// the right group is often the third or fourth, and now and then the sixth or eighth (8
  /// against 4 on the lying set: docs/pipeline.md, stage 6). Default banks of objects of 10 cm
  /// and more (one resting pose) keep one start. 1: the largest only.
  int resting_poses_starts = 8;
  /// Where stage 6 puts a hypothesis: the template's range plus the cluster score's depth
  /// offset is a z-range, and off the optical axis the range along the ray is longer by
  /// 1 / cos(theta) (rangeOnRay): true converts it. Off (today's default), an object 20
  /// degrees off the axis starts 6 % short (5 cm at 0.85 m); where that is more than the depth
  /// band, stage 6's second try moves it along the axis onto the scene (and verification then
  /// asks a collision rate above 0.6 of it). On, every start moves, and on the real LM-O frame
  /// a look-alike at its edge (an unannotated object taken for the glue) passes verification
  /// and the true glue ends ICP 9 mm off: it stays off (docs/pipeline.md, stage 6).
  bool range_along_ray = false;
  /// A scene pixel under the rendered mask belongs to the object when its depth lies within
  /// this fraction of the object's diameter of the rendered depth there. Nearer is an
  /// occluder, farther is what lies behind the object (the mask is still misplaced by up to a
  /// few centimetres at this stage).
  float depth_band_fraction = 0.3f;
  /// The scene crop that refinement and verification see: the rendered object's box grown by
  /// this fraction of its size on every side, depths within the band of the rendered range.
  float crop_margin_fraction = 0.25f;
  /// Fewer scene points than this under the mask (a black hole in the depth map, an object
  /// seen through a gap): the hypothesis is rejected.
  std::size_t min_scene_points = 50;
};
/// Throws InputError naming the bad value.
void validateInitialPoseParams(const InitialPoseParams& params);

struct RefineParams {
  /// Moving least squares smoothing of the scene crop before registration.
  bool mls = true;
  /// MLS neighbourhood radius, metres. At 0.7 m a Kinect-class sensor samples about every
  /// 1.2 mm, so 1 cm holds ~200 points: enough to average its 1-3 mm depth noise down with a
  /// quadric fit, yet small against the 10-20 cm LM-O objects, so edges and curvature survive.
  float mls_radius = 0.01f;
  int mls_polynomial_order = 2;  ///< 2: quadric fit (follows curved surfaces); 1: plane
  /// true: fit MLS only at one seed point per voxel_size voxel (the neighbourhoods still hold
  /// every point), since the voxel grid keeps one point per voxel anyway: the same smoothing
  /// for about a third of the work (LM-O crop of 8.8k points: 23 vs 68 ms). false: fit at
  /// every point, then voxel-filter (the paper's literal order).
  bool mls_at_voxel_seeds = true;
  /// MLS fits at most this many neighbours of a point (every k-th of a larger neighbourhood);
  /// 0: all of them, PCL's MovingLeastSquares exactly. A 1 cm neighbourhood at 0.7 m holds
  /// about 200 points; 64 still average the noise down 8-fold, fit a 6-coefficient quadric
  /// with 10 points to spare per coefficient, and cost a third (synthetic cup bin: poses within
  /// 0.6 mm of the full fit's; IC-BIN: the same detections).
  int mls_max_neighbours = 64;
  /// Both clouds are voxel-filtered to this leaf size (metres), so that each surface patch
  /// weighs the same in the fit whatever the sensor's or the model's sampling. 0: no filter.
  float voxel_size = 0.004f;
  /// Coarse stage: max correspondence distance = this fraction of the largest distance among
  /// the current nearest-neighbour pairs, recomputed each iteration (the paper: 90%).
  float coarse_fraction = 0.9f;
  float fine_fraction = 0.45f;  ///< fine stage, the same with 45% (the paper)
  int coarse_iterations = 30;   ///< iteration limit of the coarse stage (0: skip it)
  int fine_iterations = 30;     ///< iteration limit of the fine stage (0: skip it)
  /// The coarse stage pairs at most this many model points (every k-th of the voxel-filtered
  /// model); the fine stage pairs them all. 0: all in both. The coarse stage only brings the
  /// pose near the fine stage's reach: 250 points spread over the visible surface (a cup's is
  /// about 1,200 voxels of 4 mm) constrain six degrees of freedom many times over, and its
  /// 30 iterations then cost a fifth.
  int coarse_max_points = 250;
  /// A stage has converged when one iteration moves the pose by less than this: squared
  /// translation (m^2) and 1 - cos(rotation angle), PCL's transformation epsilon criterion.
  double convergence_epsilon = 1e-6;
  /// Fewer points than this in either filtered cloud, or fewer pairs within the threshold:
  /// no registration (converged = false).
  std::size_t min_points = 10;
  /// Baseline for comparison: > 0 replaces the two adaptive stages by one plain
  /// pcl::IterativeClosestPoint run with this fixed max correspondence distance (metres) and
  /// coarse_iterations + fine_iterations iterations. Filtering is unchanged.
  float fixed_max_correspondence_m = 0.f;
  /// The first fit, a cheap test of every start before MLS and ICP: both ICP stages on the
  /// unsmoothed crop with the coarse stage's thinned model points (about a third of a
  /// refinement's CPU time), then stage 8's collision rate, see-through share, silhouette
  /// support and image-edge support at that pose. At stage 6's pose these tests tell nothing (a later detection's
  /// start had a collision rate from 0.05); after the first fit they come close to the final
  /// ones (docs/pipeline.md, stage 7). false: every start is refined.
  bool first_fit = true;
  /// A start goes on to MLS and ICP when its first fit reaches this share of stage 8's limits:
  /// a collision rate of share x verify.threshold (a start that needs the raised rate of a
  /// second try, that rate less the same margin) and at most verify.max_see_through / share
  /// seen through.
  /// The collision rate there runs lower than after MLS (an L-shaped part: 0.34 at the first
  /// fit, 0.66 refined), so 0.85 lost detections where 0.75 kept every one (IC-BIN, LM-O,
  /// synthetic sets).
  float first_fit_share = 0.75f;
  /// ... and an image edge under first_fit_contour_share x verify.min_contour_edges of its
  /// visible outline: lower than the other tests' share because a symmetric carton's first fit
  /// can lie half a turn from the pose stage 8 settles on (a milk carton: 0.32 at the first fit,
  /// 0.93 turned).
  float first_fit_contour_share = 0.6f;
  /// ... and a silhouette support under first_fit_silhouette_share x
  /// verify.min_silhouette_support: higher than the collision test's share because the outline
  /// moves little in MLS and ICP (every later detection not pulled aside showed 0.53 or more
  /// at the first fit against 0.55 asked; the starts that failed on IC-BIN, 0.41-0.50).
  float first_fit_silhouette_share = 0.85f;
  /// A start above the collision limit whose first fit sees through at least this share of
  /// the model counts as pulled aside by a larger surface (a carton by the table it stands
  /// on: a third of its outline at the first fit, all of it after MLS and ICP), and its
  /// silhouette and see-through tests wait for stage 8. One that sees through less lies on the
  /// scene's surfaces already, and an outline without depth steps there stays without them
  /// (LM-O: 20 such starts of four objects, none a detection after MLS and ICP).
  float first_fit_pulled_see_through = 0.05f;
  /// ... and, where the mesh has colours and verify.min_colour_agreement is on, a rendering
  /// of the first fit whose chromaticity agrees with the frame's less than that limit minus
  /// first_fit_colour_margin (firstFitColours): another object of the shape in the wrong
  /// colour, which MLS and ICP do not change.
  float first_fit_colour_margin = 0.1f;
  /// A start whose first fit lies within verify.twin_distance_fraction of the diameter and
  /// this angle of a better start's first fit of its object stops: MLS and ICP bring both to
  /// one pose (LM-O: 5.1-5.9 degrees apart at the first fit, stage 8's twins or duplicates;
  /// 9.7 degrees apart, the second became the glue's detection where the first failed).
  float first_fit_twin_angle_deg = 7.5f;
  /// Of the starts whose first fits put an object's centre in one place (closer than
  /// detector.duplicate_fraction of the diameter), this many go on, the best by stage 8's score
  /// at the first fit; only one of them can be a detection, and the first fit's ranking is not
  /// the final one (1 lost an LM-O detection; refining the second only where the first failed
  /// stage 8 cost synthetic cartons their better pose). 0: all of them. A start in the place
  /// of a better start of another object (the smaller diameter's place) waits for it and stops
  /// if it passed stage 8: it would lose the place to it.
  int first_fit_per_place = 2;
};
/// Throws InputError naming the bad value.
void validateRefineParams(const RefineParams& params);

struct VerifyParams {
  /// Octree leaf size, metres. Real depth is noisy: on LM-O (object 5, about 1 m away) a
  /// correct refined pose scored 0.50 at 4 mm and 0.77 at 8 mm, a pose 2 cm off at most 0.15
  /// and 0.35 (tests/pose/verify_test.cpp). Tune with the threshold.
  float resolution = 0.004f;
  /// Accept if the collision rate exceeds this. Measured on LM-O (scene 2, image 3) at 4 mm
  /// leaves: correct refined poses 0.42-0.64, wrong ones that pass the other two tests up to 0.38.
  float threshold = 0.4f;
  /// The collision rate is counted over the model points the scene does not hide: a part
  /// 60 % in sight can collide with at most 60 % of its visible points, and a cup in a bin
  /// under another one fell under the threshold with a right pose. Stage 8 and the first fit
  /// compare hits / (points x max(1 - occluded, 1 - occlusion_credit)) with the threshold,
  /// where `occluded` is the share of points the scene lies in front of (DepthAgreement); the
  /// credit caps how much of the part may be hidden (a pose sunk into a surface also looks
  /// hidden). The reported collision_rate and the score stay hits / points. LM-O frame, banks
  /// trained `--units mm` alone: the glue found (4 -> 5 of 8, none wrong); cup bins 5151:
  /// 25 -> 28 found; the stress, lying and bracket sets unchanged (docs/history.md). 0: the
  /// paper's rate. The silhouette test counts the same way: outline samples behind something
  /// nearer show no step, right pose or not (cup bins: 1-4 more cups found a seed of 30
  /// images; LM-O, stress, lying and bracket sets unchanged).
  float occlusion_credit = 0.5f;
  float crop_margin = 0.02f;  ///< scene points within the model's box grown by this (metres) go in the octree
  /// Free-space test: a visible model point whose pixel sees the scene this much (metres)
  /// farther away cannot be there (the camera looks through it). The collision rate alone
  /// accepts a flat face of a model laid on any flat surface; the points that stick out of it
  /// then float in front of that surface.
  float see_through_tolerance = 0.015f;
  /// Accept only if at most this share of the visible model points (with scene depth) is
  /// seen through.
  float max_see_through = 0.15f;
  /// Silhouette test: an object that stands where it is claimed shows a depth step along most
  /// of its outline (the background lies farther). A model sunk into a table or a wall, with
  /// one flat face flush with it, fits the depth everywhere and has a collision rate as high
  /// as a true object's (measured on LM-O: a hole puncher laid into the paper markers, phi
  /// 0.59), but shows no step. A step is a jump of at least `silhouette_jump` metres.
  float silhouette_jump = 0.01f;
  /// Accept only if at least this share of the outline's samples (where the scene has depth
  /// on both sides, and nothing nearer outside) steps back.
  float min_silhouette_support = 0.55f;
  /// Contour test: where the outline is visible (no occluder in front), the colour image
  /// shows an edge along it, within 2 px (contourEdgeSupport). A look-alike of the right size
  /// and the wrong shape leaves much of its outline on no edge (lying seed 52: correct poses
  /// 0.55-1.00, look-alikes 0.33; LM-O: correct 0.56-0.97). Accept only if at least this share
  /// of the visible outline meets an edge. 0: off.
  float min_contour_edges = 0.45f;
  /// Size is evidence too (opt-in): the outline's support (image edges and depth steps along
  /// it, averaged) is measured again with the model scaled by 1/1.15 and 1.15 about its centre,
  /// each also moved across the view by the size change (ICP lays the part against one side of
  /// a larger look-alike). A look-alike of another size (the next screw size, a larger cup) is
  /// often explained better by one of them. With a margin m < 1, reject when a scaled model's
  /// support beats the part's own by more than m. Synthetic cup bins with copies scaled 0.8-0.9
  /// and 1.1-1.2, at 0.05: seed 9494 (held out) 19.5 % of the copies reported -> 5.2 %, no cup
  /// lost; seeds 7171 and 8383 (tuned on) 19-25 % -> 5-18 %. Off by default because real frames'
  /// partly hidden objects lose too: a correct LM-O glue (0.08 behind) and an IC-BIN cup (0.13).
  /// 1: off.
  float size_probe_margin = 1.f;
  /// Size from the depth around the outline (silhouetteScale): along each visible outline
  /// sample's normal, where the scene's depth steps back, fitted as a scaling of the outline
  /// about its centre. A model fitted into a look-alike 10-20 % larger meets those steps only
  /// past its own outline (the metal piles' larger spark-plug keys: 1.08-1.17 at most starts),
  /// the part's own pose at about 1. Reject above the limit, for parts of kSmallPartDiameterM
  /// or more trained nearer than kPileDistanceM only (partVerifyParams): their outline spans
  /// enough of a close camera's pixels. A smaller part's outline is a few matching windows
  /// across, and its holed metal depth moves the estimate (right nozzles up to 1.10). The metal
  /// piles' keys: right poses 0.98-1.03; scaled copies reported, 2 -> 1 of 46 on fresh seeds
  /// and 6 -> 3 of 78 on those looked at, no key lost (history.md, 2026-12-07). 0: off.
  float max_silhouette_scale = 1.05f;
  /// Objects compete for scene points: best score first, each accepted detection claims the
  /// scene it explains (4 x 4 pixel cells where a visible model point meets the scene depth
  /// within see_through_tolerance); one whose explained cells are more than this share
  /// claimed already by better detections is rejected (a small object laid onto a larger
  /// one's surface). 1: off.
  float max_shared_support = 0.5f;
  /// Near-symmetries (TemplateBank::near_symmetries): an accepted pose and its turned
  /// alternatives are rendered and compared with the scene's colour and depth
  /// (appearanceAgreement); an alternative replaces ICP's pose, and is refined again, when it
  /// scores at least `symmetry_margin` higher. A pose whose best rival comes within the margin
  /// is flagged ambiguous_symmetry (always so for an uncoloured mesh).
  bool resolve_symmetries = true;
  float symmetry_margin = 0.05f;
  /// Look-alike half-turns (findLookAlikeTurns): turns that map the surface onto itself
  /// within this share of the diameter but not within the near-symmetry tolerance. Such a
  /// turn does not fit the depth as well as the pose, but templates cannot tell them apart
  /// (a lying carton end for end). Each accepted pose is turned, refit by ICP from there,
  /// and the two are rendered and compared by colour and the depth residual over the whole
  /// mask; the turn replaces the pose when it scores symmetry_margin higher. 0: off.
  float look_alike_tolerance = 0.06f;
  /// The same for parts smaller than 10 cm (kSmallPartDiameterM). 0.5 takes every half-turn
  /// about the principal and model axes (up to three): a 40 mm bracket turned over is 5-10 mm
  /// off, a quarter of its diameter, yet 30-60 pixels across, on LINEMOD's 5-pixel grid and
  /// 1 mm depth steps, the templates take one for the other, and ICP cannot walk a pose over.
  /// The bracket bins: precision 0.68-0.91 without, 0.72-0.95 with (docs/evaluation.md).
  float small_part_look_alike_tolerance = 0.5f;
  /// For meshes with colours (a PLY with vertex colours): the kept pose's rendered
  /// chromaticity must agree with the frame's at least this much (a cup-shaped can, a
  /// carton's twin in other colours, a brown ape taken on a blue cup fit the depth as well as
  /// the object). -1: off.
  float min_colour_agreement = 0.2f;
  /// The same for parts smaller than 10 cm (kSmallPartDiameterM): 30-60 pixels across and a
  /// few millimetres thick, a part's depth tests say less, so its colour has to say more. On
  /// the grey bracket bins the correct poses agreed 0.50-0.96 (one in 95: 0.25) and the ones
  /// on clutter of other colours 0.25-0.40; LM-O's scans, of 10 cm and more, keep 0.2 (their
  /// correct poses agree from 0.33). -1: off.
  float small_part_min_colour_agreement = 0.45f;
  /// Share of the visible outline whose nearest image edge must lie within 1.5 px of it
  /// (outlineOnEdges): the part's own edges, not edges of about its size nearby. 0: off. On
  /// the synthetic metal piles 0.7 makes the nozzles precise (right ones 0.81-0.94, ones laid
  /// on other parts 0.56-0.64) and halves the screws' wrong detections, but the 40 mm
  /// bracket's right poses measure 0.48-0.96 (its bin bar: F1 0.95 -> 0.82) and LM-O's glue
  /// 0.42, so it is off by default (small_turned_part_min_outline_on_edges is not).
  float min_outline_on_edges = 0.f;
  /// The same for a part under 10 cm that is a body of revolution (a turned part: a nozzle, a
  /// pin, a bushing; the bank trained --symmetric or revolutionAxis() found in its
  /// near-symmetries). Its outline does not hang on the spin about its axis that depth cannot
  /// fix, so a right pose's lies on its edges, and one laid on another part's does not: on
  /// the metal piles the nozzles' wrong detections go (seeds 61-63: precision 0.14-0.63 ->
  /// 1.00, recall unchanged). A flat part's outline hangs on a pose ICP fits to little depth
  /// (the bracket's right poses measure from 0.48), so it keeps min_outline_on_edges.
  float small_turned_part_min_outline_on_edges = 0.7f;
  /// The collision rate a candidate needs when stage 6's first start paired no scene pixel and
  /// the second try moved it along the camera's axis (InitialPose::second_try_m). That move
  /// searches the whole ray for a surface, so it finds one on whatever lies there: on the LM-O
  /// frame a glue bottle placed on a box's face at the image's edge (collision 0.46); the cups
  /// the move found on the lying stress set (off-axis starts 6-9 cm short) reach 0.87-0.95.
  /// The larger of this and `threshold` counts.
  float second_try_min_collision = 0.6f;
  /// Twins: two candidates of one object whose refined centres lie closer than this share of
  /// the diameter and whose rotations differ by less than twin_angle_deg are one candidate
  /// twice; the worse is dropped before the alternatives are rendered (a small part's 64
  /// candidates x 4 starts converge on a few instances: 4.6 of a bracket bin frame's 10.4 s).
  float twin_distance_fraction = 0.05f;
  float twin_angle_deg = 5.f;
  /// Hopeless: a pose whose silhouette support is under this share of min_silhouette_support
  /// is not rendered against its alternatives (it is rejected anyway). Not more than a fifth:
  /// turned over, a bracket's outline changes enough that at half of it a correct detection
  /// was lost.
  float hopeless_support_share = 0.2f;
};
/// Throws InputError naming the bad value.
void validateVerifyParams(const VerifyParams& params);

/// The depth sensor's noise, which the scaled lengths (below) follow at the object's distance.
/// The defaults are the Kinect-like model `vkpose synth` renders with (synth.hpp).
struct SensorParams {
  float axial_sigma_at_1m = 0.0015f;  ///< axial noise sigma(z) = this * z^2, metres at 1 m
  float quantization_m = 0.001f;      ///< the depth images' step, metres
  /// Parts under 10 cm show poorly in its depth: a stereo camera's matching window merges thin
  /// structures into what lies behind them, and metal that mirrors the projector leaves holes
  /// ("close-range"). The detector then also matches small parts on their colour features
  /// alone (MatchParams::small_part_colour_alone).
  bool small_parts_unreliable = false;
};
/// Throws InputError naming the bad value.
void validateSensorParams(const SensorParams& params);

/// A named sensor profile (`--sensor`): "kinect" (the default, structured light: 1.5 mm at
/// 1 m, a 1 mm step), "primesense" (Carmine-class short range: 1.0 mm at 1 m), "realsense-d435"
/// (active stereo: 2.5 mm at 1 m), "close-range" (a D415-class stereo camera over a bin at
/// 0.3-0.5 m: 2.0 mm at 1 m; synth also renders its edges, thin parts and specular holes) or
/// "ideal" (no noise, no step); or the path of a JSON file
/// {"axial_sigma_at_1m": metres, "quantization_m": metres}. InputError for an unknown name or
/// a bad file.
SensorParams sensorProfile(const std::string& name_or_file);
/// The profile names sensorProfile() knows, the default first.
std::vector<std::string> sensorProfileNames();

/// Frames without depth (docs/pipeline.md, colour only): stages 1-3 on the colour modality
/// alone, a similarity score instead of stage 4, then each candidate's template pose fitted
/// to the image's edges (a directional chamfer fit instead of MLS + ICP) and verified by how
/// much of its outline meets an edge running along it, and by its colours.
struct ColourOnlyParams {
  /// LINEMOD similarity a match needs without depth, percent. Colour gradients alone match
  /// clutter far more often (LM-O, 8 objects: 2.6 million matches at 80 %, 19 s of similarity
  /// on lavapipe; 4.5 s at 90 %, the same objects found), but the objects of synthetic scenes,
  /// whose colours the templates were not trained on, need 80 (F1 0.27 against 0.12 at 90).
  float threshold = 80.f;
  /// Hypotheses per object that get a pose (after NMS, best LINEMOD similarity first).
  int candidates_per_object = 8;
  /// Rotation starts per hypothesis (its largest groups of template rotations), each fitted;
  /// the best supported is kept. Six rather than three: on held-out Tejani-pose sets F1 0.80
  /// -> 0.83 and LM-O's holepuncher 42 -> 8 px, for about 1.4x the fitting time.
  int starts = 6;
  /// Canny's hysteresis thresholds on the strongest channel's Sobel magnitude (L2).
  float canny_low = 40.f, canny_high = 100.f;
  /// An outline point is supported within this distance of an image edge of its orientation.
  float edge_tolerance_px = 2.f;
  /// Share of the outline points that must be supported for a pose to be accepted, 0..1.
  float min_contour_support = 0.5f;
  /// A mesh without colours posed over a surface of one colour (the frame's chromaticity under
  /// it spreads less than kMinChromaSpread, 0.05) is verified by its outline alone, this share
  /// of it on an image edge (0: off, every pose by min_contour_support over all its edges).
  /// Its rendered shading's edges need not be the frame's: on the synthetic sets looked at, the
  /// milk jug's right poses have 42-74 % of all their edges on the frame's and 86-100 % of
  /// their outline, under a chromaticity spread of 0.01-0.03; wrong poses with 85 % or more of
  /// their outline on edges lay over several colours (0.12-0.18) but for one, and the others
  /// over one colour reached 84 %. Tables 91 / 95: F1 0.84 / 0.77 -> 0.87 / 0.81; held-out
  /// tables 0.785 -> 0.794 and bins 0.40 -> 0.43 on average (history.md, 2026-12-07 night).
  float min_plain_outline_support = 0.85f;
  /// A mesh without colours posed over several colours (the spread kMinChromaSpread or more)
  /// needs this share of all its edges supported, where min_contour_support is less. A right
  /// pose of a part the mesh does not colour shows the part's one colour; on the synthetic
  /// tables and bins looked at, all 42 right milk-jug poses found lay over one colour, while
  /// 7 of the jug's 9 wrong poses lay over several (on the painted carton and cup, 0.51-0.71 of
  /// their edges supported); right jugs reach 0.34-0.76 over one colour. A printed part whose
  /// mesh has no colours is held to it too: colour only found none of IC-BIN's printed
  /// cartons right (26-230 px off against the depth path's poses), at 0.56-0.88.
  float min_uncoloured_mixed_support = 0.8f;
  /// Meshes with colours: the rendered chromaticity must agree with the frame's this much
  /// (Lin's concordance, -1..1; -1: off). Without depth most wrong poses are another object's
  /// place or clutter, which agree 0.0-0.2, where right poses agree 0.5-0.97 on synthetic sets
  /// and 0.26-0.72 on LM-O's scanned colours.
  float min_colour_agreement = 0.2f;
  /// The same for meshes whose colours vary (a painted or printed part: chromaticity spread
  /// kMinChromaSpread or more), whose right poses show their pattern: on the synthetic table
  /// and bin sets looked at, the painted carton's and cup's right poses agree 0.56-0.97 (111
  /// poses), poses on other objects and clutter mostly under 0.5. LM-O's scans vary too little
  /// for that (right poses 0.40-0.72) and keep the value above. Table and bin seed 91:
  /// precision 0.45 -> 0.64 and 0.51 -> 0.75 (history.md, 2026-12-07).
  float min_colourful_agreement = 0.5f;
  /// Each fitted pose whose outline passed is fitted again (the finer rounds) from its
  /// object's look-alike turns: the bank's near-symmetries where the mesh's colours tell them
  /// apart (a painted carton turned a quarter about its axis has the same outline) and the
  /// look-alike half-turns (VerifyParams::look_alike_tolerance); the best scored is kept.
  bool try_turns = true;
  /// ... and from the pose tilted by this angle both ways about the camera's x and y axes
  /// through its centre (degrees; 0: off): the outline fit turns little out of the image
  /// plane, and a start 15-30 degrees off stays there.
  float tilt_restart_deg = 20.f;
  /// Meshes whose colours vary (PoseObject::colourful, not symmetric): each fitted pose whose
  /// outline passed is also turned through its centre by the 23 turns of a cube about the
  /// model's axes and the 12 eighth turns about each axis, each fitted one round (10 px) and
  /// scored; this many of the best scored are fitted on with the finer rounds (0: off). The
  /// outline cannot tell a painted box upside down or a cup turned about its axis from the
  /// truth, the colours can: on the table sets looked at, fits from the true pose scored
  /// 0.6-0.94 where the kept poses, 90-180 degrees off, scored 0.2-0.5. Tables 91 / 92 / 96:
  /// F1 0.60 / 0.54 / 0.68 -> 0.66 / 0.61 / 0.78; held out (97-100) 0.66 -> 0.68 on average.
  /// A frame takes 1.1-1.7x as long (docs/colour_only.md).
  int colour_turns = 3;
  /// Rounds of these restarts. After the first, each pose that a restart improved is fitted
  /// again from its own look-alike turns and tilts (not the colour turns), until none improves
  /// or this many rounds are done (1: one round). A colour turn that found the right face
  /// leaves the pose tilted; the next round's tilt squares it up. Table sets looked at (91 /
  /// 92 / 95 / 96): F1 0.66 / 0.61 / 0.85 / 0.78 -> 0.78 / 0.67 / 0.85 / 0.88; held out (97-102)
  /// 0.72 -> 0.74 on average, bins 0.39 -> 0.42 (history.md, 2026-12-07 afternoon).
  int restart_rounds = 3;
  /// The score is multiplied by the pose's region contrast (regionContrast: how well the
  /// frame's colours tell its mask from a band around it, 0..1) to this power (0: off). The
  /// outline and the edges score a pose 6-14 px off within a few hundredths of the right one,
  /// and a smaller pose laid inside a larger object as high; the right pose separates its object
  /// from the surroundings best. On the table sets looked at, right poses had contrasts of
  /// 0.99 (median 1.00), near misses 0.93 (0.97), wrong ones 0.90; on bins 0.93 against 0.82.
  float region_contrast_power = 6.f;
};

struct DetectorParams {
  MatchParams match;
  ClusterParams cluster;
  ScoreParams score;
  NmsParams nms;
  /// Without stages 6-8 (estimate_poses false): hypotheses whose cluster score gamma is below
  /// this are dropped before NMS (a cluster on clutter, a template that fits the colour edges
  /// but not the depth).
  float min_score = 0.15f;
  /// With stages 6-8: hypotheses with gamma from this up go through NMS within their object,
  /// and the best pose_candidates_per_object of each object get a pose; verification, not
  /// gamma, then decides. On real Kinect depth at 1 m, gamma of a correct hypothesis can be as
  /// low as 0.13 (LM-O), and a cluttered object's best hypothesis can rank below hundreds of
  /// other objects' ones, so one global gamma cut and NMS across objects would lose it.
  float pose_min_score = 0.05f;
  int pose_candidates_per_object = 16;
  /// The same for parts smaller than 10 cm (kSmallPartDiameterM): their NMS keeps several
  /// hypotheses a place (NmsParams::small_part_radius_fraction), so a bin of 6-12 needs more.
  int small_part_pose_candidates = 64;
  /// Stages 6-8 (initial pose, MLS + ICP, octree verification). false: stop after NMS and
  /// report the best template's pose, unverified.
  bool estimate_poses = true;
  InitialPoseParams initial_pose;
  RefineParams refine;
  VerifyParams verify;
  /// Two accepted poses whose object centres are closer than this fraction of the smaller
  /// diameter claim the same space: only the better one is kept (two clusters of one
  /// instance that NMS kept apart in the image converge to one place after ICP).
  float duplicate_fraction = 0.3f;
  unsigned threads = 0;  ///< CPU threads for the per-hypothesis stages (0: all cores)
  SensorParams sensor;
  ColourOnlyParams colour_only;
  /// The lengths of stages 7-8 that depend on the object's size and the sensor's noise
  /// (scaledLengths() lists them) follow each object when left at their defaults: the
  /// defaults were tuned on 10-30 cm objects at 0.6-1.2 m, and a 4 cm part needs finer ones.
  /// false: every length as given.
  bool scale_lengths = true;
};
/// Throws InputError naming the first bad value of any stage.
void validateDetectorParams(const DetectorParams& params);

// ---- lengths that follow the object and the sensor -----------------------------------

/// A length parameter that follows the object: left at its default, it becomes
/// min(default, max(default * diameter / kScaleReferenceDiameter, noise_multiple * noise(z)))
/// for an object of that diameter at distance z, where noise(z) is the larger of the sensor's
/// axial sigma and its quantization step. Objects of 10 cm and more keep the default, so what
/// works today stays as it is; smaller ones get lengths in proportion to their size, but
/// never below a multiple of what the sensor can resolve there.
struct ScaledLength {
  std::string section, key;  ///< as the config file names it
  float& (*field)(DetectorParams&) = nullptr;
  float noise_multiple = 1.f;
  std::string why;
};
constexpr float kScaleReferenceDiameter = kSmallPartDiameterM;

/// Every scaled length, in pipeline order.
const std::vector<ScaledLength>& scaledLengths();

/// max(sigma(z), quantization) of the sensor at distance z (metres).
float depthNoise(const SensorParams& sensor, float distance_m);

/// `params` with each scaled length that is at its default (DetectorParams{}) set for an
/// object of `diameter_m` at `distance_m`; the others, and everything with scale_lengths
/// false, as given.
DetectorParams scaledForObject(const DetectorParams& params, float diameter_m, float distance_m);

/// One line per scaled length: its value for this object at this distance, and whether it
/// was derived or set by the user.
std::string scaledLengthsReport(const DetectorParams& params, float diameter_m, float distance_m);

// ---- the config file ------------------------------------------------------------------

/// The values a number parameter accepts: from `min` to `max`, either end open or unbounded.
/// One range per parameter: the config file, the command-line flag, Python's Config and the
/// stage's own check all test this one.
struct ValueRange {
  double min = -1e300, max = 1e300;  ///< +-1e300: unbounded (every finite value)
  bool min_open = false, max_open = false;
  bool contains(double v) const;
  std::string text() const;  ///< "[0, 1]", "(0, 100]", ">= 1", "> 0", "any"
};
/// [lo, hi]
inline ValueRange closed(double lo, double hi) { return {lo, hi, false, false}; }
/// (lo, hi]
inline ValueRange aboveUpTo(double lo, double hi) { return {lo, hi, true, false}; }
/// [lo, hi)
inline ValueRange fromBelow(double lo, double hi) { return {lo, hi, false, true}; }
/// [lo, infinity)
inline ValueRange atLeast(double lo) { return {lo, 1e300, false, false}; }
/// (lo, infinity)
inline ValueRange above(double lo) { return {lo, 1e300, true, false}; }

/// One parameter: where it lives in the file ("section": {"key": value}), what it means (with
/// its unit), the field it sets, the values it accepts and, where it has one, the `detect`
/// command-line flag that sets it too ("!--no-pose": a flag that sets a bool false).
struct ConfigField {
  std::string section, key, doc;
  std::variant<float*, double*, int*, unsigned*, std::size_t*, bool*> value;
  ValueRange range = {};
  std::string flag = {};
};

/// InputError naming `section.key`, its value and its range when a field of `params` (of
/// `section` only, when one is given) lies outside its range or is not finite.
void checkRanges(const DetectorParams& params, const std::string& section = {});

/// Every stage parameter of `params`, in pipeline order; the pointers refer into `params`.
std::vector<ConfigField> configFields(DetectorParams& params);

/// The parameters as the config file holds them, pretty-printed JSON.
std::string configJson(const DetectorParams& params);

/// A table of every parameter: section.key, default, meaning and unit.
std::string configTable(const DetectorParams& params = {});

/// `base` with the values the JSON document sets. InputError (naming `source`) for text that
/// is not JSON, an unknown section or key (the known ones listed), a value of the wrong type
/// or out of range, and parameters that fail validateDetectorParams.
DetectorParams parseConfig(const std::string& text, const std::string& source, const DetectorParams& base = {});

/// parseConfig of a file; InputError when it is missing or unreadable.
DetectorParams loadConfig(const std::string& path, const DetectorParams& base = {});

/// `from_file` overridden by every field of `from_flags` that differs from `defaults`: what a
/// command line gives wins over the config file.
DetectorParams mergeConfig(const DetectorParams& defaults, const DetectorParams& from_file,
                           const DetectorParams& from_flags);

}  // namespace vkpose
