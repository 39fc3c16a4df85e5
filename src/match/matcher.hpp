#pragma once
// Stage 2, similarity (LINEMOD section 2.5 and OpenCV's Detector::match): every template is
// scored at every position of the coarsest level, positions over the threshold are refined
// in a 16 x 16 cell window at the next finer level.
#include <chrono>
#include <cstdint>
#include <memory>
#include <vector>

#include "match/depth_gate.hpp"
#include "match/features.hpp"
#include "vkpose/bank.hpp"
#include "vkpose/config.hpp"
#include "vkpose/device.hpp"

namespace vkpose {

/// A template found in a frame.
struct Match {
  int template_id = 0;
  int x = 0, y = 0;         ///< pixels, full resolution; as OpenCV reports (may be negative)
  float similarity = 0.0f;  ///< percent
  int raw_score = 0;        ///< sum of feature responses (0..4 per feature) at the finest level
  bool operator==(const Match&) const = default;
};

/// Best first: similarity, then template id, then y, then x.
void sortMatches(std::vector<Match>& matches);

/// Templates' depth gates and a frame's anchor cells (match/depth_gate.hpp).
struct DepthPruning {
  std::vector<match::TemplateDepthGate> gates;  ///< one per template
  match::AnchorDepthCells cells;
};

/// Throws InputError for a threshold outside (0, 100] % or an outside response outside 0..4:
/// the checks the GPU matcher and the CPU reference share.
void validateMatchParams(const MatchParams& params);

/// Stage 2 on the CPU from the quantized pyramid: the reference the GPU matcher is tested
/// against. With `pruning`, only coarse positions that pass match::positionPasses.
std::vector<Match> matchTemplatesReference(const std::vector<QuantizedLevel>& pyramid,
                                           const std::vector<LinemodTemplate>& templates,
                                           const FeatureParams& feature_params, const MatchParams& params,
                                           const DepthPruning* pruning = nullptr);

/// Wall-clock of the last frame's GPU work, host side.
struct MatchTimings {
  double upload_ms = 0;   ///< template upload when the templates or the image size changed
  double features_ms = 0;    ///< stage 1: the frame features' submit
  double similarity_ms = 0;  ///< stage 2: the similarity passes' submits (coarse and refinement)
  double finish_ms = 0;   ///< host-side sorting and deduplication
  /// The GPU's own time within features_ms and similarity_ms (device timestamps; 0 where the
  /// queue writes none): the rest is recording, submitting, waiting and reading back.
  double features_kernel_ms = 0, similarity_kernel_ms = 0;
  std::size_t coarse_candidates = 0;
  /// Submits of the similarity stage: 1 unless the candidates outgrew one GPU buffer and
  /// the template chunks were split over several passes.
  std::size_t passes = 0;
  /// Similarity submits including those that overflowed and were run again (passes when
  /// none did): each overflow costs a pass's work.
  std::size_t attempts = 0;
  /// Template chunks (up to 16,384 templates each; fewer when a chunk's refinement outgrew
  /// a GPU buffer and the chunks were halved).
  std::size_t chunks = 0;
  /// Depth-guided pruning of the coarse pass (0 when off or the frame has no depth): the
  /// (template, position) pairs it has, those pruned, and those of strips skipped whole.
  uint64_t pairs = 0, pairs_pruned = 0, pairs_skipped = 0;
  double pruning_ms = 0;  ///< host side: the anchor cells and the counts
};

namespace gpu {
class Batch;
class FrameFeatures;
class Similarity;
}  // namespace gpu

/// Stages 1 and 2 on the GPU: one submit for the frame features and the first similarity
/// pass (two without GPU timestamps), then one per further pass.
class LinemodMatcher {
 public:
  LinemodMatcher(GpuContext& context, FeatureParams feature_params = {}, MatchParams params = {});
  ~LinemodMatcher();
  LinemodMatcher(const LinemodMatcher&) = delete;
  LinemodMatcher& operator=(const LinemodMatcher&) = delete;

  /// Replaces the templates (validated here; uploaded at the next match()). With `gates`
  /// (one per template) and MatchParams::depth_pruning, frames with depth are pruned.
  void setTemplates(std::vector<LinemodTemplate> templates, std::vector<match::TemplateDepthGate> gates = {});
  const std::vector<LinemodTemplate>& templates() const { return templates_; }

  std::vector<Match> match(const LinemodFrame& frame);
  /// match() in two halves, for frames in flight: submit() starts a frame's stages 1-2 on the
  /// GPU and returns at once; collect() waits for them and returns the matches (running
  /// further passes if the candidates overflowed). The host may work in between; one frame
  /// at a time. With GPU timestamps, the stage times are then the device's.
  void submit(const LinemodFrame& frame);
  std::vector<Match> collect();
  bool inFlight() const { return pending_.active; }
  const MatchTimings& lastTimings() const { return timings_; }

  /// The frame features of the last match() (for parity tests and debugging).
  gpu::FrameFeatures& frameFeatures() { return *features_; }

 private:
  GpuContext& context_;
  FeatureParams feature_params_;
  MatchParams params_;
  std::vector<LinemodTemplate> templates_;
  std::vector<match::TemplateDepthGate> gates_;  ///< empty: no pruning
  std::vector<std::pair<int, int>> depth_bands_;  ///< the gates' distinct depth intervals
  std::unique_ptr<gpu::FrameFeatures> features_;
  std::unique_ptr<gpu::Similarity> similarity_;
  std::vector<LinearMemoryLayout> layouts_;
  cv::Size uploaded_for_;  ///< frame size the templates were laid out for
  /// Template chunks per similarity pass that the last frame got through without overflowing
  /// (0: all); the next frame starts from it instead of failing its way down again.
  std::size_t chunks_per_pass_ = 0;
  MatchTimings timings_;
  std::unique_ptr<gpu::Batch> batch_;
  /// The frame between submit() and collect().
  struct Pending {
    bool active = false;     ///< submitted, not yet collected
    bool submitted = false;  ///< its GPU work went out (false: no templates)
    bool timestamps = false;
    uint32_t features_begin = 0, features_end = 0, similarity_end = 0;
    double features_record_ms = 0;
    std::chrono::steady_clock::time_point started;
    std::size_t per_pass = 0;
  } pending_;
  void submitFrame(const LinemodFrame& frame);
  std::vector<Match> collectFrame(bool wall_clock);
};

}  // namespace vkpose
