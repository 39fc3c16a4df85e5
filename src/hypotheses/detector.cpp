// The detector facade: stages 1-5 in order, a timing per stage.
#include <chrono>
#include <cmath>

#include <fmt/format.h>

#include "util/timing.hpp"
#include "vkpose/detector.hpp"
#include "vkpose/error.hpp"

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
  validateScoreParams(params_.score);
  if (!(params_.min_score >= 0.f && params_.min_score <= 1.f)) throw InputError("minimum score must be in [0, 1]");
  matcher_ = std::make_unique<LinemodMatcher>(ctx_, banks_.front().params.features, params_.match);
  matcher_->setTemplates(concatenateTemplates(banks_));
  scorer_ = std::make_unique<ClusterScorer>(ctx_);
}

Detector::~Detector() = default;

Pose templatePose(const Hypothesis& h, const MemberScore& s, const BankTemplate& t, const TemplateBank& bank,
                  const Camera& camera) {
  const Eigen::Matrix3f ray = viewingRayRotation(h.x, h.y, camera);
  // The training camera looked at the bank's centre, so the centre sits on the template's
  // optical axis; on the scene's ray it moves by the measured depth offset.
  const Eigen::Vector3f centre_t = t.pose.R * bank.centre + t.pose.t;
  const float range = centre_t.norm();
  const Eigen::Vector3f centre_s = ray * centre_t * ((range + s.depth_offset) / range);
  Pose p;
  p.R = ray * t.pose.R;
  p.t = centre_s - p.R * bank.centre;
  return p;
}

DetectionResult Detector::detect(const LinemodFrame& frame, const Camera& frame_camera) {
  validateFrame(frame, banks_.front().params.features);
  // scene_camera.json entries carry no image size: the frame's is the one that counts. A
  // principal point outside the frame means the intrinsics are for another camera.
  Camera camera = frame_camera;
  camera.width = frame.depth_mm.cols;
  camera.height = frame.depth_mm.rows;
  validateCamera(camera);
  if (camera.cx < 0 || camera.cy < 0 || camera.cx > camera.width || camera.cy > camera.height)
    throw InputError(fmt::format("the principal point ({}, {}) lies outside the {}x{} frame: wrong camera file?",
                                 camera.cx, camera.cy, camera.width, camera.height));
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
  std::vector<Match> matches = matcher_->match(frame);
  const MatchTimings& mt = matcher_->lastTimings();
  if (mt.upload_ms > 0) result.timings_ms.emplace_back("upload", mt.upload_ms);
  result.timings_ms.emplace_back("features+similarity", mt.gpu_ms);
  result.timings_ms.emplace_back("match_readback", mt.finish_ms);
  result.matches = matches.size();

  t0 = std::chrono::steady_clock::now();
  std::vector<Hypothesis> hypotheses = clusterTemplates(matches, banks_, params_.cluster);
  result.hypotheses = hypotheses.size();
  result.timings_ms.emplace_back("clustering", msSince(t0));

  t0 = std::chrono::steady_clock::now();
  const ScoreScene scene = makeScoreScene(frame.depth_mm, camera);
  scorer_->score(hypotheses, banks_, scene, params_.score);
  std::erase_if(hypotheses, [&](const Hypothesis& h) { return h.best_member < 0 || h.score < params_.min_score; });
  result.scored_hypotheses = hypotheses.size();
  result.timings_ms.emplace_back("scoring", msSince(t0));

  t0 = std::chrono::steady_clock::now();
  hypotheses = suppressNonMaxima(std::move(hypotheses), banks_, camera.fx, params_.nms);
  result.timings_ms.emplace_back("nms", msSince(t0));

  for (const auto& h : hypotheses) {
    const TemplateBank& bank = banks_[static_cast<std::size_t>(h.bank)];
    const auto best = static_cast<std::size_t>(h.best_member);
    const ClusterMember& m = h.members[best];
    const BankTemplate& t = bank.templates[static_cast<std::size_t>(m.template_index)];
    Detection d;
    d.bank = h.bank;
    d.object = bank.object;
    d.score = h.score;
    d.alpha = h.alpha;
    d.beta = h.beta;
    d.x = h.x;
    d.y = h.y;
    d.bbox = templateBox(h, t);
    d.pose = templatePose(h, h.member_scores[best], t, bank, camera);
    d.templates = static_cast<int>(h.members.size());
    d.template_index = m.template_index;
    d.similarity = m.similarity;
    result.detections.push_back(std::move(d));
  }
  result.timings_ms.emplace_back("total", msSince(total0));
  return result;
}

}  // namespace vkpose
