// The detector facade: stages 1-8 in order, a timing per stage.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>
#include <utility>

#include <fmt/format.h>

#include "gpu/batch.hpp"
#include "hypotheses/cluster_score.hpp"
#include "hypotheses/hypotheses.hpp"
#include "match/match_templates.hpp"
#include "match/matcher.hpp"
#include "pipeline/colour_only.hpp"
#include "pipeline/pipeline.hpp"
#include "pose/accept.hpp"
#include "pose/alternatives.hpp"
#include "pose/appearance.hpp"
#include "pose/candidate.hpp"
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

bool sameFeatures(const FeatureParams& a, const FeatureParams& b) {
  return a.T == b.T && a.use_colour == b.use_colour && a.use_depth == b.use_depth;
}

}  // namespace

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
  match::MatchTemplates templates = match::matchTemplates(banks_, params_.match, params_.sensor);
  matcher_->setTemplates(std::move(templates.templates), std::move(templates.gates));
  template_origins_ = std::make_unique<match::TemplateOrigins>(std::move(templates.origins));
  scorer_ = std::make_unique<ClusterScorer>(ctx_);
  objects_ = poseObjects(banks_, params_);
}

Detector::~Detector() = default;

void appendMatchTimings(const MatchTimings& t, DetectionResult& r) {
  if (t.upload_ms > 0) addStage(r.timings_ms, Stage::upload, t.upload_ms);
  if (t.pairs > 0) addStage(r.timings_ms, Stage::depth_pruning, t.pruning_ms);
  addStage(r.timings_ms, Stage::features, t.features_ms);
  addStage(r.timings_ms, Stage::similarity, t.similarity_ms);
  addStage(r.timings_ms, Stage::match_readback, t.finish_ms);
  addStage(r.kernel_ms, Stage::features, t.features_kernel_ms);
  addStage(r.kernel_ms, Stage::similarity, t.similarity_kernel_ms);
}

/// A warning for each bank trained for another focal length than the camera's (by over 10 %).
std::vector<std::string> focalLengthWarnings(const std::vector<TemplateBank>& banks, const Camera& camera) {
  std::vector<std::string> warnings;
  for (const auto& b : banks) {
    const double f_bank = 0.5 * (b.params.camera.fx + b.params.camera.fy), f = 0.5 * (camera.fx + camera.fy);
    if (std::abs(f / f_bank - 1.0) > 0.1)
      warnings.push_back(fmt::format(
          "bank '{}' was trained for a focal length of {:.0f} px, this camera has {:.0f} px: templates are "
          "scale-specific, so retrain it with this camera (vkpose train --camera)",
          b.object, f_bank, f));
  }
  return warnings;
}

/// Without stages 6-8: each hypothesis at its best template's pose (templatePose).
std::vector<Detection> templateDetections(const std::vector<Hypothesis>& hypotheses,
                                          const std::vector<TemplateBank>& banks, const Camera& camera) {
  std::vector<Detection> detections;
  for (const auto& h : hypotheses) {
    Detection d = hypothesisDetection(h, banks);
    const TemplateBank& bank = banks[static_cast<std::size_t>(h.bank)];
    const BankTemplate& t = bank.templates[static_cast<std::size_t>(d.template_index)];
    d.pose = templatePose(h, h.member_scores[static_cast<std::size_t>(h.best_member)], t, bank, camera);
    detections.push_back(std::move(d));
  }
  return detections;
}

Pose templatePose(const Hypothesis& h, const MemberScore& s, const BankTemplate& t, const TemplateBank& bank,
                  const Camera& camera) {
  // The training camera looked at the bank's centre, so the centre sits on the template's
  // optical axis; on the scene's ray it moves by the measured depth offset.
  const float range = (t.pose.R * bank.centre + t.pose.t).norm() + s.depth_offset;
  return poseAtRange(viewingRayRotation(h.x, h.y, camera) * t.pose.R, h.x, h.y, range, bank.centre, camera);
}

Camera frameCamera(const LinemodFrame& frame, const Camera& frame_camera, const FeatureParams& features) {
  validateFrame(frame, features);
  // scene_camera.json entries carry no image size: the frame's is the one that counts. A
  // principal point outside the frame means the intrinsics are for another camera.
  Camera camera = frame_camera;
  const cv::Mat& sized = frame.depth_mm.empty() ? frame.bgr : frame.depth_mm;
  camera.width = sized.cols;
  camera.height = sized.rows;
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
  if (frame.depth_mm.empty()) {  // colour only (src/pipeline/colour_only.cpp)
    in_flight_ = nullptr;
    return detectColourOnly(frame, frame_camera);
  }
  const bool submitted = matcher_->inFlight();
  in_flight_ = nullptr;
  const Camera camera = frameCamera(frame, frame_camera, banks_.front().params.features);
  if (cv::countNonZero(frame.depth_mm) == 0) throw InputError("the depth image is all zero: nothing to detect");

  DetectionResult result;
  result.warnings = focalLengthWarnings(banks_, camera);
  const auto total0 = std::chrono::steady_clock::now();
  // Started while the previous frame's CPU stages ran (detectSequence), or now.
  std::vector<Match> matches = submitted ? matcher_->collect() : matcher_->match(frame);
  match::asBankTemplateMatches(matches, *template_origins_);
  appendMatchTimings(matcher_->lastTimings(), result);
  result.matches = matches.size();
  result.match_pairs = matcher_->lastTimings().pairs;
  result.match_pairs_pruned = matcher_->lastTimings().pairs_pruned;
  result.match_pairs_skipped = matcher_->lastTimings().pairs_skipped;

  StageClock clock(ctx_);
  std::vector<Hypothesis> hypotheses = clusterTemplates(matches, banks_, params_.cluster);
  result.hypotheses = hypotheses.size();
  clock.end(Stage::clustering, result);

  const ScoreScene scene = makeScoreScene(frame.depth_mm, camera);
  scorer_->score(hypotheses, banks_, scene, params_.score);
  const float min_score = params_.estimate_poses ? params_.pose_min_score : params_.min_score;
  std::erase_if(hypotheses, [&](const Hypothesis& h) { return h.best_member < 0 || h.score < min_score; });
  result.scored_hypotheses = hypotheses.size();
  clock.end(Stage::scoring, result);

  hypotheses = nonMaximumSuppression(std::move(hypotheses), banks_, camera.fx, params_);
  clock.end(Stage::nms, result);

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
    result.detections = templateDetections(hypotheses, banks_, camera);
  }
  addStage(result.timings_ms, Stage::total, msSince(total0));
  return result;
}

void Detector::estimatePoses(const std::vector<Hypothesis>& clusters, const ScoreScene& scene,
                             const cv::Mat& frame_bgr, DetectionResult& result) {
  const PoseFrame frame = poseFrame(scene.camera, scene.depth_m, frame_bgr);
  const unsigned threads = params_.threads;
  const auto wall0 = std::chrono::steady_clock::now();
  const double cpu0 = util::processCpuMs();
  StageClock clock(ctx_);
  // Stage 6: one or more rotation starts a hypothesis, each rendered and moved onto the scene.
  std::vector<PoseCandidate> candidates = startCandidates(clusters, banks_, frame.camera, params_);
  attachRenderers();
  initialPoses(candidates, objects_, frame, params_);
  clock.end(Stage::initial_pose, result);
  // Stage 7: a cheap first fit of every start stops those that cannot pass stage 8; then MLS
  // smoothing of each crop and ICP (timed apart: they cost about the same), and stage 8's
  // measurements, in rounds: a start in the place of another object's better start waits
  // for its stage 8 (nextRound).
  if (params_.refine.first_fit) {
    firstFits(candidates, frame, threads);
    screenStarts(candidates);
    firstFitColours(candidates, objects_, frame, threads);
    clock.end(Stage::first_fit, result);
  }
  std::pair<double, double> mls_ms, icp_ms, measure_ms;
  const auto add = [](std::pair<double, double>& sum, std::pair<double, double> ms) {
    sum.first += ms.first;
    sum.second += ms.second;
  };
  for (auto round = nextRound(candidates, banks_, params_.duplicate_fraction); !round.empty();
       round = nextRound(candidates, banks_, params_.duplicate_fraction)) {
    smoothSceneCrops(candidates, round, threads);
    add(mls_ms, clock.split());
    refineCandidates(candidates, round, threads);
    add(icp_ms, clock.split());
    verifyCandidates(candidates, round, frame, threads);
    add(measure_ms, clock.split());
  }
  for (const auto& [stage, ms] : {std::pair{Stage::mls, mls_ms}, std::pair{Stage::icp, icp_ms}}) {
    addStage(result.timings_ms, stage, ms.first);
    addStage(result.kernel_ms, stage, ms.second);
  }
  // Stage 8: the collision rate and the depth and outline tests (measured above); the poses
  // that pass are rendered against their near-symmetric turns and look-alikes (twins of
  // better ones spared), then accepted or rejected, and the accepted compete for places and
  // the scene.
  StageClock symmetries(ctx_);
  markTwins(candidates, banks_, params_.verify);
  for (auto& c : candidates) resolveNearSymmetries(c, objects_[c.bank()], frame, params_);
  for (auto& c : candidates) resolveLookAlikes(c, objects_[c.bank()], frame, params_);
  const auto symmetries_ms = symmetries.split();
  // Refined: the candidates MLS and ICP ran on; their CPU time includes every first fit.
  for (const auto& c : candidates) {
    if (c.measured) ++result.refined_candidates;
    if (c.initial.ok) result.refine_cpu_ms += c.cpu_ms;
  }
  acceptPoses(candidates, banks_, frame.camera, params_, result);
  // Verification: its measurements in the rounds, plus this, less the symmetries timed apart.
  clock.end(Stage::verification, result, {symmetries_ms.first - measure_ms.first, symmetries_ms.second - measure_ms.second});
  addStage(result.timings_ms, Stage::symmetries, symmetries_ms.first);
  addStage(result.kernel_ms, Stage::symmetries, symmetries_ms.second);
  result.pose_wall_ms = msSince(wall0);
  result.pose_cpu_ms = util::processCpuMs() - cpu0;
  result.pose_threads = util::threadsFor(candidates.size(), threads);
}

void Detector::attachRenderers() {
  if (!renderers_.empty()) return;
  // One workspace for all banks: they render one after another, and each renderer with its
  // own held up to about 170 MiB of full-frame outputs and staging (1.3 GiB for 8 objects).
  const auto workspace = makeRenderWorkspace(ctx_);
  // Each renders a simplified copy of its mesh (the surface within about 0.2 % of the diameter):
  // scanned and CAD meshes carry about a triangle per pixel at these distances, and the
  // rasterizer's cost is their setup. The IC-BIN cup: 61,766 -> 3,938 faces, stage 6
  // 175 -> 62 ms a frame, the same detections (docs/performance.md).
  for (std::size_t b = 0; b < banks_.size(); ++b) {
    const Mesh m = simplifiedForRendering(banks_[b].mesh, kDetectionRenderError * banks_[b].diameter);
    renderers_.push_back(std::make_unique<MeshRenderer>(ctx_, m, workspace));
    objects_[b].renderer = renderers_.back().get();
  }
}

}  // namespace vkpose
