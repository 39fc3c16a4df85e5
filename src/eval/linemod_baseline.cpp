// The LINEMOD baseline: raw matches as detections, each with its template's pose, the best
// few per object.
#include <chrono>

#include <fmt/format.h>

#include "eval/baselines.hpp"
#include "hypotheses/cluster_score.hpp"
#include "hypotheses/hypotheses.hpp"
#include "match/features.hpp"
#include "match/matcher.hpp"
#include "pipeline/pipeline.hpp"
#include "util/timing.hpp"
#include "vkpose/bank.hpp"
#include "vkpose/detector.hpp"
#include "vkpose/device.hpp"
#include "vkpose/error.hpp"
#include "vkpose/geometry.hpp"

namespace vkpose {

LinemodBaseline::LinemodBaseline(GpuContext& ctx, std::vector<TemplateBank> banks, LinemodBaselineParams params)
    : ctx_(ctx), banks_(std::move(banks)), params_(params) {
  if (banks_.empty()) throw InputError("the LINEMOD baseline needs at least one template bank");
  if (params_.max_per_object < 0)
    throw InputError(fmt::format("detections per object must be 0 (all) or more, not {}", params_.max_per_object));
  for (const auto& b : banks_)
    if (b.templates.empty()) throw InputError("bank '" + b.object + "' has no templates");
  matcher_ = std::make_unique<LinemodMatcher>(ctx_, banks_.front().params.features, params_.match);
  matcher_->setTemplates(concatenateTemplates(banks_));
  if (params_.depth_offset) scorer_ = std::make_unique<ClusterScorer>(ctx_);
}

LinemodBaseline::~LinemodBaseline() = default;

DetectionResult LinemodBaseline::detect(const LinemodFrame& frame, const Camera& frame_camera) {
  const Camera camera = frameCamera(frame, frame_camera, banks_.front().params.features);

  DetectionResult result;
  const auto total0 = std::chrono::steady_clock::now();
  const std::vector<Match> matches = matcher_->match(frame);  // best first
  appendMatchTimings(matcher_->lastTimings(), result);
  result.matches = matches.size();

  // Each match is a one-member hypothesis centred where the match puts the object's centre:
  // the form templatePose() and the cluster score's depth offset take.
  const auto t0 = std::chrono::steady_clock::now();
  const TemplateIndex index(banks_);
  std::vector<Hypothesis> singles;
  singles.reserve(matches.size());
  std::vector<int> kept(banks_.size(), 0);
  for (const Match& m : matches) {  // best first: the first max_per_object of each bank are its best
    const int bank = index.bankOf(m.template_id);
    if (params_.max_per_object > 0 && kept[static_cast<std::size_t>(bank)]++ >= params_.max_per_object) continue;
    const int local = index.localId(m.template_id);
    const BankTemplate& t = banks_[static_cast<std::size_t>(bank)].templates[static_cast<std::size_t>(local)];
    Hypothesis h;
    h.bank = bank;
    h.x = static_cast<float>(m.x) + t.anchor_x;
    h.y = static_cast<float>(m.y) + t.anchor_y;
    h.distance = t.distance;
    h.members.push_back({local, m.x, m.y, m.similarity, h.x, h.y});
    singles.push_back(std::move(h));
  }
  if (scorer_ && !singles.empty()) {
    ScoreParams one;
    one.max_members = 1;
    scorer_->scoreMembers(singles, banks_, makeScoreScene(frame.depth_mm, camera), one);
  }
  for (const Hypothesis& h : singles) {
    const TemplateBank& bank = banks_[static_cast<std::size_t>(h.bank)];
    const ClusterMember& m = h.members.front();
    const BankTemplate& t = bank.templates[static_cast<std::size_t>(m.template_index)];
    const MemberScore offset = h.member_scores.empty() ? MemberScore{} : h.member_scores.front();
    Detection d;
    d.bank = h.bank;
    d.object = bank.object;
    d.score = m.similarity / 100.f;
    d.x = h.x;
    d.y = h.y;
    d.bbox = templateBox(h, t);
    d.pose = templatePose(h, offset, t, bank, camera);
    d.templates = 1;
    d.template_index = m.template_index;
    d.similarity = m.similarity;
    result.detections.push_back(std::move(d));
  }
  result.hypotheses = result.scored_hypotheses = result.detections.size();
  addStage(result.timings_ms, Stage::poses, util::msSince(t0));
  addStage(result.timings_ms, Stage::total, util::msSince(total0));
  return result;
}

}  // namespace vkpose
