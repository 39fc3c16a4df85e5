#pragma once
// Stage 2 on the GPU: template headers and feature offsets on the device, coarse scoring of
// every template, indirect refinement of the candidates, all recorded into the frame's batch.
// Refinement scores each unit (one template, 4 finer-level rows, one 16-cell block) that
// some candidate's window covers once (shaders/refine_grid.glsl), runs of neighbouring
// units together, then picks each candidate's best position from the units.
#include <memory>
#include <vector>

#include "gpu/batch.hpp"
#include "match/depth_gate.hpp"
#include "match/match_geometry.hpp"

namespace vkpose::gpu {

class FrameFeatures;

class Similarity {
 public:
  explicit Similarity(const GpuContext& ctx);
  ~Similarity();

  /// Lays the templates out for `layouts` (one per level) and uploads them through `batch`.
  /// `gates`: one per template (depth-guided pruning), or empty.
  void setTemplates(Batch& batch, const std::vector<LinemodTemplate>& templates, const FeatureParams& feature_params,
                    const MatchParams& params, const std::vector<LinearMemoryLayout>& layouts,
                    const std::vector<match::TemplateDepthGate>& gates = {});
  /// Each template's coarse range (match::coarseRange), as setTemplates() laid it out.
  const std::vector<match::CoarseRange>& coarseRanges() const { return ranges_; }
  /// The frame's anchor cells and its depth bands' boxes for depth-guided pruning (empty
  /// cells: none), uploaded through `batch` for the record()s that follow.
  void setDepth(Batch& batch, const match::AnchorDepthCells& cells, const std::vector<match::BandBox>& boxes);

  /// Template chunks (each one dispatch group); record() covers a range of them.
  std::size_t chunkCount() const { return chunks_.size(); }

  /// Records coarse scoring and refinement of the template chunks [begin, end).
  void record(Batch& batch, const FrameFeatures& features, std::size_t begin, std::size_t end);

  /// After the batch's submit: the candidates, or with refinement the candidates whose
  /// refinement passed the threshold with their refinements (their coarse score left 0).
  /// Returns false when the candidate list or the unit list overflowed (they grow; run the
  /// pass again). When the candidate list is already as large as one binding allows, full()
  /// turns true: the pass must cover fewer chunks.
  bool read(std::vector<match::CoarseCandidate>& candidates, std::vector<match::RefineResult>& refined);
  /// The coarse candidates of the last read() pass, all of them (refined or not).
  std::size_t coarseCount() const { return coarse_count_; }
  bool full() const { return full_; }
  /// After a read() that returned false: a chunk's refinement units outgrew one binding of
  /// unit scores. splitChunks() halves the chunks (false when they are single templates
  /// already); setTemplates() must then lay the templates out again.
  bool unitsFull() const { return units_full_; }
  bool splitChunks();
  /// Candidates one pass can hold at most (one binding's worth).
  std::size_t maxCandidates() const { return max_capacity_; }

 private:
  struct Chunk {
    int first_template = 0, template_count = 0;
    std::size_t coarse_invocations = 0;  ///< the most any template needs: (rows / 2) x (columns / 48) of its range
    Buffer headers[2], offsets[2];
  };
  struct Kernels;
  const GpuContext& ctx_;
  std::unique_ptr<Kernels> kernels_;
  std::vector<Chunk> chunks_;
  std::vector<LinearMemoryLayout> layouts_;
  std::vector<match::CoarseRange> ranges_;
  int depth_cells_x_ = 0, depth_cells_y_ = 0;  ///< 0: no pruning this frame
  int depth_boxes_at_ = 0;                      ///< where the band boxes start in depth_, in uints
  FeatureParams feature_params_;
  uint32_t capacity_ = 1u << 16;       // candidate slots
  uint32_t max_capacity_ = 0;          // candidate slots one binding can hold
  bool full_ = false;                  // the last pass overflowed max_capacity_
  bool units_full_ = false;            // the last pass overflowed max_unit_capacity_
  std::size_t chunk_templates_ = 16384;  // most templates of a chunk: 16384 until splitChunks()
  uint32_t unit_capacity_ = 1u << 16;  // unit slots of one chunk
  uint32_t max_unit_capacity_ = 0;     // every unit of the largest chunk, or one binding's worth
  std::size_t template_bands_ = 0;     // template bands of the largest chunk
  std::size_t block_words_ = 0;        // and its block mark words
  std::size_t column_words_ = 0;       // and its column mark words
  std::size_t coarse_count_ = 0;
  Buffer candidates_, refined_, depth_;
  Buffer columns_, occupied_, blocks_, bases_, shifts_, runs_, scores_, state_;
};

}  // namespace vkpose::gpu
