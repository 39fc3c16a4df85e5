// The detector facade: stages 1-8 in order, a timing per stage.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>
#include <utility>

#include <fmt/format.h>

#include "hypotheses/cluster_score.hpp"
#include "hypotheses/hypotheses.hpp"
#include "match/matcher.hpp"
#include "pipeline/pipeline.hpp"
#include "pose/appearance.hpp"
#include "pose/initial_pose.hpp"
#include "pose/point_cloud.hpp"
#include "pose/refine.hpp"
#include "pose/verify.hpp"
#include "render/render.hpp"
#include "render/simplify.hpp"
#include "util/parallel.hpp"
#include "util/timing.hpp"
#include "vkpose/bank.hpp"
#include "vkpose/detector.hpp"
#include "vkpose/device.hpp"
#include "vkpose/error.hpp"
#include "vkpose/geometry.hpp"

namespace vkpose {

namespace {
using util::msSince;

/// Where a pose puts a point of the object's frame (the bank's centre, mostly).
Eigen::Vector3f placed(const Pose& pose, const Eigen::Vector3f& point) { return pose.R * point + pose.t; }

/// Two candidates whose refined poses lie this close (share of the diameter, between the
/// centres) and turn by less than this are one candidate twice (Detector::estimatePoses).
constexpr float kTwinDistance = 0.05f;
constexpr float kTwinAngleRad = 0.0873f;  // 5 degrees

/// The collision rate a candidate needs when stage 6's first start paired no scene pixel and
/// the second try moved it along the camera's axis (InitialPose::second_try_m). That move
/// searches the whole ray for a surface, so it finds one on whatever lies there: on the LM-O
/// frame a glue bottle placed on a box's face at the image's edge (collision 0.46); the cups
/// the move found on the lying stress set (off-axis starts 6-9 cm short) reach 0.87-0.95.
constexpr float kSecondTryMinCollision = 0.6f;

/// A verified pose's score: the collision rate, times the share not seen through, times the
/// outline's support (Detection::score).
float poseScore(float collision_rate, float see_through, float silhouette_support) {
  return collision_rate * (1.f - see_through) * silhouette_support;
}

/// What decides between two verified poses of one object in one place: the score, times the
/// dense fit of the chosen look-alike alternative (its depth fit, colour and depth residual
/// over the whole mask) where that check ran. On the small-part bins a bracket turned over
/// a real one scored 0.58-0.78 against 0.47-0.72 for the right pose, but fit densely 0.25-0.76
/// against 0.63-0.93.
float sameObjectRank(const Detection& d) {
  const auto& alts = d.look_alike_alternatives;
  const auto chosen = static_cast<std::size_t>(d.look_alike_chosen);
  return chosen < alts.size() ? d.score * alts[chosen].score : d.score;
}

/// Whether two poses' centres lie closer than duplicate_fraction of the smaller diameter.
bool samePlace(const Detection& a, const Detection& b, const std::vector<TemplateBank>& banks,
               float duplicate_fraction) {
  const TemplateBank& ba = banks.at(static_cast<std::size_t>(a.bank));
  const TemplateBank& bb = banks.at(static_cast<std::size_t>(b.bank));
  const Eigen::Vector3f ca = placed(a.pose, ba.centre), cb = placed(b.pose, bb.centre);
  return (ca - cb).norm() < duplicate_fraction * std::min(ba.diameter, bb.diameter);
}

bool sameFeatures(const FeatureParams& a, const FeatureParams& b) {
  return a.T == b.T && a.use_colour == b.use_colour && a.use_depth == b.use_depth;
}

/// What stages 1-5 know about a hypothesis (no pose yet).
Detection hypothesisDetection(const Hypothesis& h, const std::vector<TemplateBank>& banks) {
  const TemplateBank& bank = banks[static_cast<std::size_t>(h.bank)];
  const ClusterMember& m = h.members[static_cast<std::size_t>(h.best_member)];
  Detection d;
  d.bank = h.bank;
  d.object = bank.object;
  d.score = h.score;
  d.gamma = h.score;
  d.alpha = h.alpha;
  d.beta = h.beta;
  d.x = h.x;
  d.y = h.y;
  d.bbox = templateBox(h, bank.templates[static_cast<std::size_t>(m.template_index)]);
  d.templates = static_cast<int>(h.members.size());
  d.template_index = m.template_index;
  d.similarity = m.similarity;
  return d;
}

/// The image box and centre of the posed visible model.
void placeInImage(Detection& d, const PointCloud& model_points, const Eigen::Vector3f& centre, const Camera& camera) {
  cv::Rect2f box;
  bool first = true;
  for (const auto& p : model_points) {
    const Eigen::Vector3f c = placed(d.pose, p);
    if (!(c.z() > 0.f)) continue;
    const Eigen::Vector2f uv = camera.project(c);
    const cv::Rect2f px(uv.x(), uv.y(), 1.f, 1.f);
    box = first ? px : (box | px);
    first = false;
  }
  if (!first) d.bbox = box;
  const Eigen::Vector3f c = placed(d.pose, centre);
  if (c.z() > 0.f) {
    const Eigen::Vector2f uv = camera.project(c);
    d.x = uv.x();
    d.y = uv.y();
  }
}

/// Of a pose (alternatives[0]) and its alternatives, the one kept: the pose stays unless the
/// best alternative scores `margin` higher. Also by how much the kept one beat the best other.
std::pair<std::size_t, float> chooseAlternative(const std::vector<SymmetryAlternative>& alternatives, float margin) {
  const auto best = static_cast<std::size_t>(
      std::max_element(alternatives.begin(), alternatives.end(),
                       [](const auto& x, const auto& y) { return x.score < y.score; }) -
      alternatives.begin());
  float rival = -1.f;
  for (std::size_t k = 0; k < alternatives.size(); ++k)
    if (k != best) rival = std::max(rival, alternatives[k].score);
  const std::size_t chosen = best != 0 && alternatives[best].score >= alternatives[0].score + margin ? best : 0;
  return {chosen, alternatives[chosen].score - (chosen == best ? rival : alternatives[best].score)};
}

}  // namespace

void rejectSameObjectDuplicates(std::vector<Detection>& verified, const std::vector<TemplateBank>& banks,
                                float duplicate_fraction) {
  std::vector<std::size_t> order(verified.size());
  for (std::size_t k = 0; k < order.size(); ++k) order[k] = k;
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    return sameObjectRank(verified[a]) > sameObjectRank(verified[b]);
  });
  std::vector<std::size_t> kept;
  for (const std::size_t x : order) {
    Detection& d = verified[x];
    if (!d.rejection.empty()) continue;
    const auto better = std::find_if(kept.begin(), kept.end(), [&](std::size_t y) {
      return verified[y].bank == d.bank && samePlace(verified[y], d, banks, duplicate_fraction);
    });
    if (better == kept.end())
      kept.push_back(x);
    else
      d.rejection = fmt::format("the same place as a better {} detection", verified[*better].object);
  }
}

Detector::Detector(GpuContext& ctx, std::vector<TemplateBank> banks, DetectorParams params)
    : ctx_(ctx), banks_(std::move(banks)), params_(std::move(params)) {
  if (banks_.empty()) throw InputError("the detector needs at least one template bank");
  for (const auto& b : banks_) {
    if (b.templates.empty()) throw InputError("bank '" + b.object + "' has no templates");
    if (!sameFeatures(b.params.features, banks_.front().params.features))
      throw InputError("banks '" + banks_.front().object + "' and '" + b.object +
                       "' were trained with different pyramids or modalities; retrain one of them");
  }
  validateDetectorParams(params_);
  matcher_ = std::make_unique<LinemodMatcher>(ctx_, banks_.front().params.features, params_.match);
  matcher_->setTemplates(concatenateTemplates(banks_), match::templateDepthGates(banks_));
  scorer_ = std::make_unique<ClusterScorer>(ctx_);
  bounding_radius_.assign(banks_.size(), 0.f);
  for (std::size_t b = 0; b < banks_.size(); ++b)
    for (const auto& v : banks_[b].mesh.vertices)
      bounding_radius_[b] = std::max(bounding_radius_[b], (v - banks_[b].centre).norm());
  for (const auto& b : banks_) colourful_.push_back(meshChromaSpread(b.mesh) >= kMinChromaSpread);
  // Look-alike half-turns: about 0.1 s a mesh, so found here rather than stored (banks of
  // every version get them, and the tolerance stays a detection setting).
  look_alike_turns_.assign(banks_.size(), {});
  if (params_.verify.resolve_symmetries)
    util::parallelFor(
        banks_.size(),
        [&](std::size_t b) {
          const TemplateBank& bank = banks_[b];
          if (bank.symmetric) return;  // scored with ADI: turns do not count against it
          const float from = std::max(bank.params.near_symmetry_tolerance, 0.01f) * bank.diameter;
          const float share = isSmallPart(bank.diameter) ? params_.verify.small_part_look_alike_tolerance
                                                         : params_.verify.look_alike_tolerance;
          look_alike_turns_[b] = findLookAlikeTurns(bank.mesh, from, share * bank.diameter);
        },
        params_.threads);
}

Detector::~Detector() = default;

void appendMatchTimings(const MatchTimings& t, StageTimings& to) {
  if (t.upload_ms > 0) to.emplace_back("upload", t.upload_ms);
  if (t.pairs > 0) to.emplace_back("depth_pruning", t.pruning_ms);
  to.emplace_back("features", t.features_ms);
  to.emplace_back("similarity", t.similarity_ms);
  to.emplace_back("match_readback", t.finish_ms);
}

Pose templatePose(const Hypothesis& h, const MemberScore& s, const BankTemplate& t, const TemplateBank& bank,
                  const Camera& camera) {
  // The training camera looked at the bank's centre, so the centre sits on the template's
  // optical axis; on the scene's ray it moves by the measured depth offset.
  const float range = placed(t.pose, bank.centre).norm() + s.depth_offset;
  return poseAtRange(viewingRayRotation(h.x, h.y, camera) * t.pose.R, h.x, h.y, range, bank.centre, camera);
}

Camera frameCamera(const LinemodFrame& frame, const Camera& frame_camera, const FeatureParams& features) {
  validateFrame(frame, features);
  // scene_camera.json entries carry no image size: the frame's is the one that counts. A
  // principal point outside the frame means the intrinsics are for another camera.
  Camera camera = frame_camera;
  camera.width = frame.depth_mm.cols;
  camera.height = frame.depth_mm.rows;
  validateCamera(camera);
  if (camera.cx < 0 || camera.cy < 0 || camera.cx > camera.width || camera.cy > camera.height)
    throw InputError(fmt::format("the principal point ({}, {}) lies outside the {}x{} frame: wrong camera file?",
                                 camera.cx, camera.cy, camera.width, camera.height));
  return camera;
}

DetectionResult Detector::detect(const LinemodFrame& frame, const Camera& frame_camera) {
  return detectFrame(frame, frame_camera, nullptr);
}

std::vector<DetectionResult> Detector::detectSequence(const std::vector<LinemodFrame>& frames,
                                                      const std::vector<Camera>& cameras) {
  if (frames.size() != cameras.size())
    throw InputError(fmt::format("{} frames but {} cameras", frames.size(), cameras.size()));
  std::vector<DetectionResult> results;
  results.reserve(frames.size());
  for (std::size_t i = 0; i < frames.size(); ++i)
    results.push_back(detectFrame(frames[i], cameras[i], i + 1 < frames.size() ? &frames[i + 1] : nullptr));
  return results;
}

DetectionResult Detector::detectFrame(const LinemodFrame& frame, const Camera& frame_camera, const LinemodFrame* next) {
  // A frame in flight that is not this one (an earlier frame threw before collecting it)
  // is finished and dropped.
  if (matcher_->inFlight() && in_flight_ != &frame) (void)matcher_->collect();
  const bool submitted = matcher_->inFlight();
  in_flight_ = nullptr;
  const Camera camera = frameCamera(frame, frame_camera, banks_.front().params.features);
  if (cv::countNonZero(frame.depth_mm) == 0) throw InputError("the depth image is all zero: nothing to detect");

  DetectionResult result;
  for (const auto& b : banks_) {
    const double f_bank = 0.5 * (b.params.camera.fx + b.params.camera.fy), f = 0.5 * (camera.fx + camera.fy);
    if (std::abs(f / f_bank - 1.0) > 0.1)
      result.warnings.push_back(fmt::format(
          "bank '{}' was trained for a focal length of {:.0f} px, this camera has {:.0f} px: templates are "
          "scale-specific, so retrain it with this camera (vkpose train --camera)",
          b.object, f_bank, f));
  }
  auto t0 = std::chrono::steady_clock::now();
  const auto total0 = t0;
  // Started while the previous frame's CPU stages ran (detectSequence), or now.
  std::vector<Match> matches = submitted ? matcher_->collect() : matcher_->match(frame);
  appendMatchTimings(matcher_->lastTimings(), result.timings_ms);
  result.matches = matches.size();
  result.match_pairs = matcher_->lastTimings().pairs;
  result.match_pairs_pruned = matcher_->lastTimings().pairs_pruned;
  result.match_pairs_skipped = matcher_->lastTimings().pairs_skipped;

  t0 = std::chrono::steady_clock::now();
  std::vector<Hypothesis> hypotheses = clusterTemplates(matches, banks_, params_.cluster);
  result.hypotheses = hypotheses.size();
  result.timings_ms.emplace_back("clustering", msSince(t0));

  t0 = std::chrono::steady_clock::now();
  const ScoreScene scene = makeScoreScene(frame.depth_mm, camera);
  scorer_->score(hypotheses, banks_, scene, params_.score);
  const float min_score = params_.estimate_poses ? params_.pose_min_score : params_.min_score;
  std::erase_if(hypotheses, [&](const Hypothesis& h) { return h.best_member < 0 || h.score < min_score; });
  result.scored_hypotheses = hypotheses.size();
  result.timings_ms.emplace_back("scoring", msSince(t0));

  t0 = std::chrono::steady_clock::now();
  if (params_.estimate_poses) {
    // Within each object, then the best few of each object (see pose_min_score): objects
    // compete after verification, in 3D.
    NmsParams nms = params_.nms;
    nms.across_objects = false;
    std::vector<Hypothesis> all;  // for the runners-up
    if (nms.runner_up_share > 0.f) all = hypotheses;
    hypotheses = suppressNonMaxima(std::move(hypotheses), banks_, camera.fx, nms);
    std::vector<int> taken(banks_.size(), 0);
    std::erase_if(hypotheses, [&](const Hypothesis& h) {  // best first
      const auto b = static_cast<std::size_t>(h.bank);
      const int most = isSmallPart(banks_[b].diameter) ? params_.small_part_pose_candidates
                                                        : params_.pose_candidates_per_object;
      return taken[b]++ >= most;
    });
    // After the cap: a runner-up rides with a survivor that gets a pose.
    for (auto& h : runnersUp(all, hypotheses, banks_, camera.fx, nms)) hypotheses.push_back(std::move(h));
  } else {
    // No verification to remove a small part's duplicates: one hypothesis a place for all.
    NmsParams nms = params_.nms;
    nms.small_part_radius_fraction = nms.radius_fraction;
    hypotheses = suppressNonMaxima(std::move(hypotheses), banks_, camera.fx, nms);
  }
  result.timings_ms.emplace_back("nms", msSince(t0));

  // Frames in flight: the GPU is done with this frame (matching, cluster scores), so the next
  // frame's stages 1-2 start there now and run while this frame's CPU stages do. A next frame
  // the matcher refuses is left for its own turn to report.
  if (next) {
    try {
      matcher_->submit(*next);
      in_flight_ = next;
    } catch (const InputError&) {
    }
  }

  if (params_.estimate_poses) {
    estimatePoses(hypotheses, scene, frame.bgr, result);
  } else {
    for (const auto& h : hypotheses) {
      Detection d = hypothesisDetection(h, banks_);
      const auto best = static_cast<std::size_t>(h.best_member);
      const BankTemplate& t = banks_[static_cast<std::size_t>(h.bank)].templates[static_cast<std::size_t>(d.template_index)];
      d.pose = templatePose(h, h.member_scores[best], t, banks_[static_cast<std::size_t>(h.bank)], camera);
      result.detections.push_back(std::move(d));
    }
  }
  result.timings_ms.emplace_back("total", msSince(total0));
  return result;
}

void Detector::estimatePoses(const std::vector<Hypothesis>& clusters, const ScoreScene& scene,
                             const cv::Mat& frame_bgr, DetectionResult& result) {
  // Colour for the near-symmetries' check; a frame without it (depth only) compares depth.
  const cv::Mat scene_bgr = frame_bgr.type() == CV_8UC3 && frame_bgr.size() == scene.depth_m.size()
                                ? frame_bgr
                                : cv::Mat(scene.depth_m.size(), CV_8UC3, cv::Scalar::all(0));
  const Camera& camera = scene.camera;
  // Stage 6: rotations (one or two starts a hypothesis: second_start_by_fit), then one render
  // call per bank, then the translations in parallel. From here on a candidate is a start.
  auto t0 = std::chrono::steady_clock::now();
  std::vector<Hypothesis> hypotheses;
  std::vector<Detection> dets;
  std::vector<Pose> rendered;
  for (const Hypothesis& h : clusters) {
    const TemplateBank& bank = banks_[static_cast<std::size_t>(h.bank)];
    const int starts = std::max(isSmallPart(bank.diameter) ? params_.initial_pose.small_part_starts : 1,
                                bank.params.views.other_ups.empty() ? 1 : params_.initial_pose.resting_poses_starts);
    const InitialRotation rot = initialRotation(h, bank, camera, params_.initial_pose, params_.score, starts);
    const auto start = [&](const Eigen::Matrix3f& R, int votes) {
      hypotheses.push_back(h);
      dets.push_back(hypothesisDetection(h, banks_));
      dets.back().rotation_votes = votes;
      rendered.push_back(poseOnViewingRay(R, h, bank, camera, params_.initial_pose.range_along_ray));
    };
    start(rot.R, rot.group_size);
    for (const RotationStart& s : rot.more) start(s.R, s.votes);
    if (rot.by_fit) start(rot.by_fit->R, rot.by_fit->votes);
  }
  const std::size_t n = hypotheses.size();
  if (renderers_.empty()) {
    // One workspace for all banks: they render one after another, and each renderer with its
    // own held up to about 170 MiB of full-frame outputs and staging (1.3 GiB for 8 objects).
    const auto workspace = makeRenderWorkspace(ctx_);
    // Each renders a simplified copy of its mesh (the surface within about 0.2 % of the diameter):
    // scanned and CAD meshes carry about a triangle per pixel at these distances, and the
    // rasterizer's cost is their setup. The IC-BIN cup: 61,766 -> 3,938 faces, stage 6
    // 175 -> 62 ms a frame, the same detections (docs/performance.md).
    for (const auto& b : banks_) {
      const Mesh m = simplifiedForRendering(b.mesh, kDetectionRenderError * b.diameter);
      renderers_.push_back(std::make_unique<MeshRenderer>(ctx_, m, workspace));
    }
  }
  // Each candidate renders in its own window (projectedWindow: the box of the object's
  // bounding sphere), one small submit each: a full-frame rendering per candidate cost more
  // than the rest of stage 6.
  std::vector<Rendering> renderings(n);
  std::vector<cv::Rect> windows(n);
  for (std::size_t i = 0; i < n; ++i) {
    const auto b = static_cast<std::size_t>(hypotheses[i].bank);
    windows[i] = projectedWindow(rendered[i], banks_[b].centre, bounding_radius_[b], camera);
    if (windows[i].empty()) continue;  // initialTranslation says why
    renderings[i] = std::move(renderers_[b]->render(windowCamera(camera, windows[i]), {rendered[i]}).front());
  }
  std::vector<InitialPose> initial(n);
  util::parallelFor(
      n,
      [&](std::size_t i) {
        if (windows[i].empty()) {
          initial[i].pose = rendered[i];
          initial[i].why = "the model renders outside the image";
          return;
        }
        const float diameter = banks_[static_cast<std::size_t>(hypotheses[i].bank)].diameter;
        initial[i] = initialTranslation(renderings[i], rendered[i], scene.depth_m, camera, diameter,
                                        params_.initial_pose, windows[i]);
        renderings[i] = {};
      },
      params_.threads);
  result.timings_ms.emplace_back("initial_pose", msSince(t0));

  // The lengths of stages 7-8 for each candidate's object at its distance (scaledForObject:
  // the defaults for objects of 10 cm and more), and a small part's own colour test.
  std::vector<RefineParams> refine_params(n);
  std::vector<VerifyParams> verify_params(n);
  for (std::size_t i = 0; i < n; ++i) {
    const float diameter = banks_[static_cast<std::size_t>(hypotheses[i].bank)].diameter;
    const DetectorParams scaled = scaledForObject(params_, diameter, rendered[i].t.z());
    refine_params[i] = scaled.refine;
    verify_params[i] = scaled.verify;
    if (isSmallPart(diameter)) verify_params[i].min_colour_agreement = params_.verify.small_part_min_colour_agreement;
    if (initial[i].second_try_m != 0.f)
      verify_params[i].threshold = std::max(verify_params[i].threshold, kSecondTryMinCollision);
  }

  // Stage 7: MLS smoothing of each crop, then ICP (timed apart: they cost about the same).
  t0 = std::chrono::steady_clock::now();
  std::vector<double> cpu_ms(n, 0.0);  // per candidate, stages 7-8
  std::vector<PointCloud> smoothed(n);
  util::parallelFor(
      n,
      [&](std::size_t i) {
        if (!initial[i].ok) return;
        const auto start = std::chrono::steady_clock::now();
        const RefineParams& rp = refine_params[i];
        smoothed[i] = rp.mls ? smoothMls(initial[i].scene_points, rp.mls_radius, rp.mls_polynomial_order,
                                         rp.mls_at_voxel_seeds ? rp.voxel_size : 0.f, rp.mls_max_neighbours)
                             : initial[i].scene_points;
        cpu_ms[i] += msSince(start);
      },
      params_.threads);
  result.timings_ms.emplace_back("mls", msSince(t0));
  t0 = std::chrono::steady_clock::now();
  std::vector<RefineResult> refined(n);
  util::parallelFor(
      n,
      [&](std::size_t i) {
        if (!initial[i].ok) return;
        const auto start = std::chrono::steady_clock::now();
        RefineParams icp_params = refine_params[i];
        icp_params.mls = false;  // done above
        refined[i] = refinePose(initial[i].model_points, smoothed[i], initial[i].pose, icp_params);
        cpu_ms[i] += msSince(start);
      },
      params_.threads);
  result.timings_ms.emplace_back("icp", msSince(t0));

  // Stage 8: the collision rate of the refined visible model against the raw scene crop.
  t0 = std::chrono::steady_clock::now();
  std::vector<VerifyResult> verified(n);
  std::vector<DepthAgreement> agreement(n);
  std::vector<float> support(n, 0.f), contour(n, 0.f);
  const ImageEdges edges = imageEdges(scene_bgr);
  std::vector<std::vector<int>> explained(n);  // scene cells each pose explains, for the competition below
  const auto verifyCandidate = [&](std::size_t i) {
    const auto start = std::chrono::steady_clock::now();
    const PointCloud model = transformed(initial[i].model_points, refined[i].pose);
    const VerifyParams& vp = verify_params[i];
    verified[i] = verifyPose(model, initial[i].scene_points, vp);
    agreement[i] = depthAgreement(model, scene.depth_m, camera, vp.see_through_tolerance);
    const auto outline = outlineSamples(model, camera, scene.depth_m.size());
    support[i] = silhouetteSupport(outline, scene.depth_m, vp.silhouette_jump);
    contour[i] = contourEdgeSupport(outline, edges, scene.depth_m, vp.silhouette_jump);
    explained[i] = supportCells(model, scene.depth_m, camera, vp.see_through_tolerance);
    cpu_ms[i] += msSince(start);
  };
  util::parallelFor(
      n,
      [&](std::size_t i) {
        if (initial[i].ok) verifyCandidate(i);
      },
      params_.threads);

  // Render and compare: each pose that passed the collision test and its near-symmetric
  // alternatives render in one window (GPU, one submit per candidate) and are compared with
  // the scene's colour and depth. A clear winner other than ICP's pose is refined from there
  // and verified again; the kept pose's colour agreement is a test of its own (look-alikes of
  // the right shape and the wrong colours). Meshes without colour and symmetry skip it.
  const auto symmetries0 = std::chrono::steady_clock::now();
  // Twins: candidates that ICP brought to the same pose as a better one (a small part's 64
  // candidates x 4 starts converge on a few instances). The duplicate test below would drop
  // them anyway; dropping them here spares each its renderings and refits, which were most
  // of a bracket bin frame (4.6 of 10.4 s).
  std::vector<char> twin(n, 0);
  {
    const auto preliminary = [&](std::size_t i) {
      return poseScore(verified[i].collision_rate, agreement[i].seen_through, support[i]);
    };
    std::vector<std::size_t> order;
    for (std::size_t i = 0; i < n; ++i)
      if (initial[i].ok && verified[i].accepted) order.push_back(i);
    std::stable_sort(order.begin(), order.end(),
                     [&](std::size_t a, std::size_t b) { return preliminary(a) > preliminary(b); });
    std::vector<std::size_t> kept;
    for (const std::size_t i : order) {
      const auto b = static_cast<std::size_t>(hypotheses[i].bank);
      const Pose& p = refined[i].pose;
      for (const std::size_t k : kept) {
        const Pose& q = refined[k].pose;
        if (hypotheses[k].bank != hypotheses[i].bank ||
            (placed(p, banks_[b].centre) - placed(q, banks_[b].centre)).norm() > kTwinDistance * banks_[b].diameter ||
            Eigen::AngleAxisf(p.R.transpose() * q.R).angle() > kTwinAngleRad)
          continue;
        twin[i] = 1;
        break;
      }
      if (!twin[i]) kept.push_back(i);
    }
  }
  // Hopeless: a pose whose outline shows under a fifth of the depth step the test asks for;
  // its renderings and refits are spared too. Not more than a fifth: turned over, a bracket's
  // outline changes enough that at half of it a correct detection was lost (docs/pipeline.md).
  const auto hopeless = [&](std::size_t i) {
    return support[i] < 0.2f * verify_params[i].min_silhouette_support;
  };
  for (std::size_t i = 0; i < n; ++i) {
    const auto b = static_cast<std::size_t>(hypotheses[i].bank);
    const auto& symmetries = banks_[b].near_symmetries;
    if (!initial[i].ok || !verified[i].accepted || twin[i] || hopeless(i)) continue;
    Detection& d = dets[i];
    const bool resolve = params_.verify.resolve_symmetries && !symmetries.empty();
    if (!colourful_[b] && resolve) {
      // No colours that vary (none, or LM-O's scans, which vary too little): nothing to
      // compare the turns by but depth, and they fit it within the training tolerance by
      // construction (ICP has had its say): listed, not rendered (on IC-BIN rendering the
      // cup's 7 turns cost 230 ms a frame to say "ambiguous").
      d.symmetry_alternatives.resize(1 + symmetries.size());
      for (std::size_t k = 0; k < symmetries.size(); ++k) {
        d.symmetry_alternatives[k + 1].angle_deg = symmetries[k].angle_deg;
        d.symmetry_alternatives[k + 1].axis = symmetries[k].axis;
      }
      d.symmetry_compared = false;
      d.ambiguous_symmetry = true;
    }
    // Colours that vary too little to tell turns apart still tell the object from a
    // look-alike of another colour: then only the pose itself is rendered and compared.
    const bool turns = colourful_[b] && resolve;
    const bool colour_test = !banks_[b].mesh.colours.empty() && verify_params[i].min_colour_agreement > -1.f;
    if (!turns && !colour_test) continue;
    std::vector<Pose> poses{refined[i].pose};
    if (turns)
      for (const auto& s : symmetries) poses.push_back(compose(refined[i].pose, s.transform()));
    cv::Rect window;
    for (const auto& p : poses) window |= projectedWindow(p, banks_[b].centre, bounding_radius_[b], camera);
    if (window.empty()) continue;
    const auto views = renderers_[b]->render(windowCamera(camera, window), poses);
    std::vector<SymmetryAlternative> alts;
    bool informative = false;
    for (std::size_t k = 0; k < poses.size(); ++k) {
      const AppearanceAgreement a =
          appearanceAgreement(views[k], window, scene_bgr, scene.depth_m, verify_params[i].see_through_tolerance, true);
      SymmetryAlternative alt;
      if (k > 0) alt.angle_deg = symmetries[k - 1].angle_deg, alt.axis = symmetries[k - 1].axis;
      alt.depth_fit = a.depth_fit;
      alt.colour = a.colour;
      alt.score = a.score;
      alts.push_back(alt);
      informative = informative || a.colour_informative;
    }
    const float margin = params_.verify.symmetry_margin;
    const auto [chosen, won_by] = chooseAlternative(alts, margin);
    if (informative) d.colour_agreement = alts[chosen].colour;
    if (turns) {
      d.symmetry_chosen = static_cast<int>(chosen);
      d.symmetry_margin = won_by;
      d.ambiguous_symmetry = d.symmetry_margin < margin;
      d.symmetry_alternatives = std::move(alts);
    }
    if (chosen == 0) continue;
    // The turned pose shows other faces of the model: ICP and verification take those.
    initial[i].model_points = visibleModelPoints(views[chosen], poses[chosen], camera, window);
    RefineParams icp_params = refine_params[i];
    icp_params.mls = false;
    icp_params.coarse_iterations = 0;  // a turn of the surface onto itself: only the fine fit is left
    const auto start = std::chrono::steady_clock::now();
    refined[i] = refinePose(initial[i].model_points, smoothed[i], poses[chosen], icp_params);
    cpu_ms[i] += msSince(start);
    verifyCandidate(i);
  }
  // Look-alike half-turns (a carton end for end, a jug flank for flank): the templates look
  // alike, so stage 6 may settle on either, and the turn is a centimetre off, so ICP cannot
  // walk from one to the other. Each accepted pose is turned, refit from there, and the two
  // are rendered and compared: colour where it counts, and the depth residual over the whole
  // mask (both fit within the see-through tolerance; the wrong one sits further off).
  for (std::size_t i = 0; i < n; ++i) {
    const auto b = static_cast<std::size_t>(hypotheses[i].bank);
    const auto& turns = look_alike_turns_[b];
    if (turns.empty() || !initial[i].ok || !verified[i].accepted || twin[i] || hopeless(i)) continue;
    const auto windowOf = [&](const std::vector<Pose>& poses) {
      cv::Rect window;
      for (const auto& p : poses) window |= projectedWindow(p, banks_[b].centre, bounding_radius_[b], camera);
      return window;
    };
    std::vector<Pose> starts;
    for (const auto& h : turns) starts.push_back(compose(refined[i].pose, h.transform()));
    const cv::Rect start_window = windowOf(starts);
    if (start_window.empty()) continue;
    const auto start_views = renderers_[b]->render(windowCamera(camera, start_window), starts);
    RefineParams icp_params = refine_params[i];
    icp_params.mls = false;
    std::vector<RefineResult> refits(turns.size());
    const auto start = std::chrono::steady_clock::now();
    util::parallelFor(
        turns.size(),
        [&](std::size_t k) {
          refits[k] = refinePose(visibleModelPoints(start_views[k], starts[k], camera, start_window), smoothed[i],
                                 starts[k], icp_params);
        },
        params_.threads);
    cpu_ms[i] += msSince(start);
    // Each refit with the near-symmetries' turns too where colour can tell them (a carton
    // end for end shows another painted face on top): pose 0 is the kept one, then per
    // look-alike turn its refit composed with each near-symmetry.
    const bool compose_turns = colourful_[b] && params_.verify.resolve_symmetries;
    const auto& symmetries = banks_[b].near_symmetries;
    const std::size_t family = 1 + (compose_turns ? symmetries.size() : 0);
    std::vector<Pose> poses{refined[i].pose};
    for (const auto& r : refits) {
      poses.push_back(r.pose);
      if (compose_turns)
        for (const auto& sym : symmetries) poses.push_back(compose(r.pose, sym.transform()));
    }
    const cv::Rect window = windowOf(poses);
    if (window.empty()) continue;
    const auto views = renderers_[b]->render(windowCamera(camera, window), poses);
    const float tolerance = verify_params[i].see_through_tolerance;
    std::vector<SymmetryAlternative> alts(1 + turns.size());
    std::vector<std::size_t> member(alts.size(), 0);  // the pose (index into poses) each alternative stands for
    bool informative = false;
    for (std::size_t k = 0; k < poses.size(); ++k) {
      const AppearanceAgreement a =
          appearanceAgreement(views[k], window, scene_bgr, scene.depth_m, tolerance, colourful_[b]);
      SymmetryAlternative alt;
      const std::size_t g = k == 0 ? 0 : 1 + (k - 1) / family;  // 0: the kept pose, g: turns[g - 1]
      if (g > 0) alt.angle_deg = turns[g - 1].angle_deg, alt.axis = turns[g - 1].axis;
      alt.depth_fit = a.depth_fit;
      alt.colour = a.colour;
      alt.depth_residual_m = a.depth_residual_m;
      alt.score = a.score * std::max(0.f, 1.f - a.depth_residual_m / std::max(tolerance, 1e-6f));
      informative = informative || a.colour_informative;
      if (k == 0 || k == 1 + (g - 1) * family || alt.score > alts[g].score) alts[g] = alt, member[g] = k;
    }
    const auto [chosen, won_by] = chooseAlternative(alts, params_.verify.symmetry_margin);
    Detection& d = dets[i];
    d.look_alike_chosen = static_cast<int>(chosen);
    d.look_alike_margin = won_by;
    if (chosen != 0 && informative) d.colour_agreement = alts[chosen].colour;
    d.look_alike_alternatives = std::move(alts);
    if (chosen == 0) continue;
    // Verified as any pose is, from the model surface its own rendering shows; a composed
    // near-symmetry is a few millimetres off, so the fine fit runs once more from there.
    const std::size_t k = member[chosen];
    initial[i].model_points = visibleModelPoints(views[k], poses[k], camera, window);
    if (k == 1 + (chosen - 1) * family) {
      refined[i] = refits[chosen - 1];
    } else {
      icp_params.coarse_iterations = 0;
      const auto again = std::chrono::steady_clock::now();
      refined[i] = refinePose(initial[i].model_points, smoothed[i], poses[k], icp_params);
      cpu_ms[i] += msSince(again);
    }
    verifyCandidate(i);
  }
  const double symmetries_ms = msSince(symmetries0);
  for (std::size_t i = 0; i < n; ++i)
    if (initial[i].ok) ++result.refined_candidates, result.refine_cpu_ms += cpu_ms[i];

  std::vector<Detection> accepted;
  std::vector<std::vector<int>> accepted_cells;  // explained[i] of accepted[k]
  for (std::size_t i = 0; i < n; ++i) {
    Detection& d = dets[i];
    const TemplateBank& bank = banks_[static_cast<std::size_t>(d.bank)];
    if (!initial[i].ok) {
      d.pose = rendered[i];
      d.rejection = initial[i].why;
      result.rejected.push_back(std::move(d));
      continue;
    }
    d.pose = refined[i].pose;
    d.icp_fitness = refined[i].fitness;
    d.icp_iterations = refined[i].iterations;
    d.collision_rate = verified[i].collision_rate;
    d.see_through = agreement[i].seen_through;
    d.depth_fit = agreement[i].fits;
    d.silhouette_support = support[i];
    d.contour_edges = contour[i];
    d.score = poseScore(d.collision_rate, d.see_through, d.silhouette_support);
    placeInImage(d, initial[i].model_points, bank.centre, camera);
    const VerifyParams& vp = verify_params[i];
    if (twin[i])
      d.rejection = fmt::format("the same pose as a better {} candidate", bank.object);
    else if (!verified[i].accepted)
      d.rejection = fmt::format("collision rate {:.2f} is not above {:.2f}", d.collision_rate, vp.threshold);
    else if (d.see_through > vp.max_see_through)
      d.rejection = fmt::format("the camera sees through {:.0f}% of the model (at most {:.0f}%)", 100 * d.see_through,
                                100 * vp.max_see_through);
    else if (d.silhouette_support < vp.min_silhouette_support)
      d.rejection = fmt::format("only {:.0f}% of the outline shows a depth step (at least {:.0f}%)",
                                100 * d.silhouette_support, 100 * vp.min_silhouette_support);
    else if (d.contour_edges < vp.min_contour_edges)
      d.rejection = fmt::format("only {:.0f}% of its visible outline meets an edge in the image (at least {:.0f}%): "
                                "something else of its size?",
                                100 * d.contour_edges, 100 * vp.min_contour_edges);
    else if (d.colour_agreement < vp.min_colour_agreement)
      d.rejection = fmt::format("its colours do not match the scene's (agreement {:.2f}, at least {:.2f}): "
                                "something else of its shape?",
                                d.colour_agreement, vp.min_colour_agreement);
    if (!d.rejection.empty()) {
      result.rejected.push_back(std::move(d));
      continue;
    }
    d.verified = true;
    accepted.push_back(std::move(d));
    accepted_cells.push_back(std::move(explained[i]));
  }
  // Two poses in one place: the better one stays (NMS works on image centres; after ICP two
  // clusters of one instance can meet). First among one object's own poses, ranked by the
  // score times the dense fit its look-alike check measured where it ran (sameObjectRank);
  // then across objects by the score alone (only some objects have that fit).
  // Then objects compete for the scene: best first, a detection whose explained cells are
  // mostly claimed by better ones (another object's surface) goes.
  rejectSameObjectDuplicates(accepted, banks_, params_.duplicate_fraction);
  std::vector<std::size_t> order(accepted.size());
  for (std::size_t k = 0; k < order.size(); ++k) order[k] = k;
  std::stable_sort(order.begin(), order.end(),
                   [&](std::size_t a, std::size_t b) { return accepted[a].score > accepted[b].score; });
  std::map<int, std::size_t> claimed;  // scene cell -> index into result.detections
  for (const std::size_t a : order) {
    Detection& d = accepted[a];
    const Detection* taken = nullptr;
    for (const auto& k : result.detections)
      if (samePlace(k, d, banks_, params_.duplicate_fraction)) {
        taken = &k;
        break;
      }
    if (taken) d.rejection = fmt::format("the same place as a better {} detection", taken->object);
    if (!d.rejection.empty()) {
      d.verified = false;
      result.rejected.push_back(std::move(d));
      continue;
    }
    // The better detection that claimed most of this one's scene, and how much it claimed.
    const auto& cells = accepted_cells[a];
    std::map<std::size_t, std::size_t> shared_with;
    std::size_t shared = 0;
    for (const int cell : cells)
      if (const auto it = claimed.find(cell); it != claimed.end()) ++shared, ++shared_with[it->second];
    const float share = cells.empty() ? 0.f : static_cast<float>(shared) / static_cast<float>(cells.size());
    if (share > params_.verify.max_shared_support) {
      const auto most = std::max_element(shared_with.begin(), shared_with.end(),
                                         [](const auto& x, const auto& y) { return x.second < y.second; });
      d.verified = false;
      d.rejection = fmt::format("{:.0f}% of the scene it explains is explained by better detections (at most {:.0f}%), "
                                "most by a {} detection",
                                100 * share, 100 * params_.verify.max_shared_support,
                                result.detections[most->first].object);
      result.rejected.push_back(std::move(d));
      continue;
    }
    for (const int cell : cells) claimed.emplace(cell, result.detections.size());
    result.detections.push_back(std::move(d));
  }
  result.timings_ms.emplace_back("verification", msSince(t0) - symmetries_ms);
  result.timings_ms.emplace_back("symmetries", symmetries_ms);
}

}  // namespace vkpose
