// LinemodMatcher: stages 1 and 2 on the GPU, one command buffer and one submit per frame.
#include <chrono>

#include "match/frame_features_gpu.hpp"
#include "match/similarity_gpu.hpp"
#include "util/timing.hpp"
#include "vkpose/error.hpp"
#include "vkpose/matcher.hpp"

namespace vkpose {

namespace {
using util::msSince;
}  // namespace

LinemodMatcher::LinemodMatcher(GpuContext& context, FeatureParams feature_params, MatchParams params)
    : context_(context), feature_params_(std::move(feature_params)), params_(params) {
  validateFeatureParams(feature_params_);
  if (!(params_.threshold > 0.0f && params_.threshold <= 100.0f))
    throw InputError("match threshold " + std::to_string(params_.threshold) + " % is outside (0, 100]");
  features_ = std::make_unique<gpu::FrameFeatures>(context_, feature_params_);
  similarity_ = std::make_unique<gpu::Similarity>(context_);
}

LinemodMatcher::~LinemodMatcher() = default;

void LinemodMatcher::setTemplates(std::vector<LinemodTemplate> templates) {
  validateTemplates(templates, feature_params_);
  templates_ = std::move(templates);
  uploaded_for_ = {};
}

std::vector<Match> LinemodMatcher::match(const LinemodFrame& frame) {
  validateFrame(frame, feature_params_);
  timings_ = {};
  if (templates_.empty()) return {};
  const cv::Size size = feature_params_.use_colour ? frame.bgr.size() : frame.depth_mm.size();
  gpu::Batch batch(context_);
  auto t0 = std::chrono::steady_clock::now();
  if (size != uploaded_for_) {
    layouts_ = match::makeLayouts(templates_, feature_params_, size.width, size.height);
    similarity_->setTemplates(batch, templates_, feature_params_, params_, layouts_);
    batch.submit();
    uploaded_for_ = size;
    timings_.upload_ms = msSince(t0);
  }
  std::vector<match::CoarseCandidate> candidates;
  std::vector<match::RefineResult> refined;
  for (int attempt = 0;; ++attempt) {
    t0 = std::chrono::steady_clock::now();
    features_->record(batch, frame, layouts_);
    similarity_->record(batch, *features_);
    batch.submit();
    timings_.gpu_ms += msSince(t0);
    if (similarity_->read(candidates, refined)) break;
    if (attempt == 3) throw DeviceError("the candidate list keeps overflowing; raise the match threshold");
  }
  t0 = std::chrono::steady_clock::now();
  timings_.coarse_candidates = candidates.size();
  auto matches = match::finishMatches(candidates, refined, templates_, feature_params_, params_);
  timings_.finish_ms = msSince(t0);
  return matches;
}

}  // namespace vkpose
