// LinemodMatcher: stages 1 and 2 on the GPU: one submit for the frame features, one per
// similarity pass.
#include <algorithm>
#include <chrono>

#include "match/frame_features_gpu.hpp"
#include "match/matcher.hpp"
#include "match/similarity_gpu.hpp"
#include "util/timing.hpp"
#include "vkpose/bank.hpp"
#include "vkpose/device.hpp"
#include "vkpose/error.hpp"

namespace vkpose {

namespace {
using util::msSince;
}  // namespace

LinemodMatcher::LinemodMatcher(GpuContext& context, FeatureParams feature_params, MatchParams params)
    : context_(context), feature_params_(std::move(feature_params)), params_(params) {
  validateFeatureParams(feature_params_);
  validateMatchParams(params_);
  features_ = std::make_unique<gpu::FrameFeatures>(context_, feature_params_);
  similarity_ = std::make_unique<gpu::Similarity>(context_);
}

LinemodMatcher::~LinemodMatcher() = default;

void LinemodMatcher::setTemplates(std::vector<LinemodTemplate> templates,
                                  std::vector<match::TemplateDepthGate> gates) {
  validateTemplates(templates, feature_params_);
  if (!gates.empty() && gates.size() != templates.size())
    throw InputError("depth pruning needs one gate per template: " + std::to_string(gates.size()) + " gates for " +
                     std::to_string(templates.size()) + " templates");
  templates_ = std::move(templates);
  gates_ = std::move(gates);
  depth_bands_ = match::numberDepthBands(gates_);
  uploaded_for_ = {};
  chunks_per_pass_ = 0;
}

std::vector<Match> LinemodMatcher::match(const LinemodFrame& frame) {
  submit(frame);
  return collectFrame(true);
}

std::vector<Match> LinemodMatcher::collect() { return collectFrame(false); }

void LinemodMatcher::submit(const LinemodFrame& frame) {
  if (pending_.active) throw std::logic_error("LinemodMatcher::submit: a frame is in flight; collect() it first");
  validateFrame(frame, feature_params_);
  timings_ = {};
  pending_ = {};
  if (templates_.empty()) {
    pending_.active = true;
    return;
  }
  try {
    submitFrame(frame);
  } catch (...) {
    // Nothing half-recorded may reach the next frame's submit.
    pending_ = {};
    batch_.reset();
    throw;
  }
  pending_.active = true;
  pending_.submitted = true;
}

void LinemodMatcher::submitFrame(const LinemodFrame& frame) {
  const cv::Size size = feature_params_.use_colour ? frame.bgr.size() : frame.depth_mm.size();
  if (!batch_) batch_ = std::make_unique<gpu::Batch>(context_);
  gpu::Batch& batch = *batch_;
  auto t0 = std::chrono::steady_clock::now();
  if (size != uploaded_for_) {
    layouts_ = match::makeLayouts(templates_, feature_params_, size.width, size.height);
    similarity_->setTemplates(batch, templates_, feature_params_, params_, layouts_, gates_);
    batch.submit();
    uploaded_for_ = size;
    chunks_per_pass_ = 0;
    timings_.upload_ms = msSince(t0);
  }
  // Depth-guided pruning: the frame's anchor cells go up with it; the counts are the host's.
  t0 = std::chrono::steady_clock::now();
  const auto cells = params_.depth_pruning && !gates_.empty()
                         ? match::anchorDepthCells(frame.depth_mm, layouts_.back(), static_cast<int>(layouts_.size()) - 1)
                         : match::AnchorDepthCells{};
  const auto boxes = match::bandBoxes(cells, depth_bands_);
  similarity_->setDepth(batch, cells, boxes);
  if (!cells.empty()) {
    const auto count = match::countPruning(cells, gates_, boxes, similarity_->coarseRanges());
    timings_.pairs = count.pairs;
    timings_.pairs_pruned = count.pruned;
    timings_.pairs_skipped = count.skipped;
    timings_.pruning_ms = msSince(t0);
  }
  // One pass over all template chunks, unless the candidates outgrow what one binding holds
  // (many banks at a low threshold): then passes over fewer chunks each, features computed
  // once. A frame starts with the pass size the last one ended with: an overflowing pass
  // costs as much as one that fits.
  const std::size_t chunks = similarity_->chunkCount();
  pending_.per_pass = chunks_per_pass_ > 0 ? std::min(chunks_per_pass_, chunks) : chunks;
  // Features and the first similarity pass in one submit: GPU timestamps split its time,
  // features taking their recording (the frame's conversion and copy) and their device time.
  // Without timestamps, features go in a submit of their own. Either way they stay on the
  // device for every pass.
  t0 = std::chrono::steady_clock::now();
  pending_.timestamps = batch.timestamps();
  if (pending_.timestamps) pending_.features_begin = batch.timestamp();
  features_->record(batch, frame, layouts_, params_.outside_response);
  if (pending_.timestamps) pending_.features_end = batch.timestamp();
  pending_.features_record_ms = msSince(t0);
  if (!pending_.timestamps) {
    batch.submit();
    timings_.features_ms = msSince(t0);
    t0 = std::chrono::steady_clock::now();
  }
  similarity_->record(batch, *features_, 0, std::min(chunks, pending_.per_pass));
  if (pending_.timestamps) pending_.similarity_end = batch.timestamp();
  batch.flush();
  pending_.started = t0;
}

std::vector<Match> LinemodMatcher::collectFrame(bool wall_clock) {
  if (!pending_.active) throw std::logic_error("LinemodMatcher::collect: no frame in flight; submit() one first");
  const Pending p = pending_;
  pending_ = {};
  if (!p.submitted) return {};  // no templates
  gpu::Batch& batch = *batch_;
  std::vector<match::CoarseCandidate> candidates, pass_candidates;
  std::vector<match::RefineResult> refined, pass_refined;
  std::size_t chunks = similarity_->chunkCount();
  std::size_t per_pass = p.per_pass;
  std::size_t most_candidates = 0;  // of one pass
  std::size_t coarse_candidates = 0;
  for (std::size_t begin = 0, attempt = 0, pass = 0; begin < chunks; ++pass) {
    const std::size_t end = std::min(chunks, begin + per_pass);
    if (pass == 0) {
      // Submitted by submit(). Run frame by frame (match()), the stages share the wall time
      // from its start; with other work in between (frames in flight), similarity takes
      // its device time.
      batch.wait();
      if (p.timestamps) {
        timings_.features_kernel_ms = batch.millisecondsBetween(p.features_begin, p.features_end);
        timings_.similarity_kernel_ms = batch.millisecondsBetween(p.features_end, p.similarity_end);
        timings_.features_ms = p.features_record_ms + timings_.features_kernel_ms;
        timings_.similarity_ms = wall_clock ? std::max(0.0, msSince(p.started) - timings_.features_ms)
                                            : batch.millisecondsBetween(p.features_end, p.similarity_end);
      } else {
        timings_.similarity_ms = msSince(p.started);
      }
    } else {
      const auto t0 = std::chrono::steady_clock::now();
      const double device0 = gpu::deviceMilliseconds(batch.context());
      similarity_->record(batch, *features_, begin, end);
      batch.submit();
      timings_.similarity_ms += msSince(t0);
      timings_.similarity_kernel_ms += gpu::deviceMilliseconds(batch.context()) - device0;
    }
    ++timings_.attempts;
    if (similarity_->read(pass_candidates, pass_refined)) {
      most_candidates = std::max(most_candidates, similarity_->coarseCount());
      coarse_candidates += similarity_->coarseCount();
      candidates.insert(candidates.end(), pass_candidates.begin(), pass_candidates.end());
      refined.insert(refined.end(), pass_refined.begin(), pass_refined.end());
      begin = end;
      attempt = 0;
      ++timings_.passes;
      continue;
    }
    if (similarity_->unitsFull()) {
      // A chunk's refinement outgrew a binding: the templates again in smaller chunks, and
      // the frame's passes from the start (its features stay).
      if (!similarity_->splitChunks())
        throw DeviceError("one template's refinement needs more units than a GPU buffer holds; raise the match threshold");
      similarity_->setTemplates(batch, templates_, feature_params_, params_, layouts_, gates_);
      batch.submit();
      chunks = similarity_->chunkCount();
      per_pass = chunks;
      candidates.clear();
      refined.clear();
      most_candidates = 0;
      coarse_candidates = 0;
      begin = 0;
      attempt = 0;
      continue;
    }
    if (similarity_->full()) {
      if (end - begin == 1)
        throw DeviceError("one template chunk finds more candidates than a GPU buffer holds; raise the match threshold");
      per_pass = std::max<std::size_t>(1, (end - begin) / 2);
    } else if (++attempt == 4) {
      throw DeviceError("the candidate list keeps overflowing; raise the match threshold");
    }
  }
  // Passes that stayed under half a binding could cover twice the chunks next time.
  chunks_per_pass_ = most_candidates < similarity_->maxCandidates() / 2 ? std::min(chunks, 2 * per_pass) : per_pass;
  const auto t0 = std::chrono::steady_clock::now();
  timings_.chunks = chunks;
  timings_.coarse_candidates = coarse_candidates;
  auto matches = match::finishMatches(candidates, refined, templates_, feature_params_, params_);
  timings_.finish_ms = msSince(t0);
  return matches;
}

}  // namespace vkpose
