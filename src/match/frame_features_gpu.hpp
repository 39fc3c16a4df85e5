#pragma once
// Stage 1 on the GPU: records the feature kernels of every pyramid level into a batch and
// keeps the buffers, so tests can compare each one with the CPU reference.
#include <array>
#include <memory>
#include <vector>

#include "gpu/batch.hpp"
#include "match/features.hpp"

namespace vkpose::gpu {

class FrameFeatures {
 public:
  FrameFeatures(const GpuContext& ctx, const FeatureParams& params);
  ~FrameFeatures();

  /// Records uploads and kernels for `frame` into `batch`; linear memories use `layouts`, and
  /// their cells outside the image hold `outside_response` (MatchParams) in every bin.
  void record(Batch& batch, const LinemodFrame& frame, const std::vector<LinearMemoryLayout>& layouts,
              int outside_response);

  /// Only the quantized labels of every level (no spreading, no linear memories), and with
  /// `magnitudes` the colour gradient's squared magnitude per pixel too: what training picks
  /// its features from (src/training/view_features.cpp).
  void recordQuantization(Batch& batch, const LinemodFrame& frame, bool magnitudes);

  const Buffer& labels(std::size_t level, int modality) const { return levels_[level].labels[modality]; }
  /// Linear memory of a level, a nibble per cell (responses are 0..4): cell c of the layout
  /// is bits 4 (c % 2) .. 4 (c % 2) + 3 of byte c / 2. The similarity kernels' texel fetches,
  /// not their arithmetic, set their pace, and nibbles halve the fetches.
  const Buffer& memory(std::size_t level) const { return levels_[level].memory; }
  cv::Size size(std::size_t level) const { return levels_[level].size; }

  /// Records downloads of the label images into `out` (valid after batch.submit()).
  void downloadLabels(Batch& batch, std::vector<QuantizedLevel>& out) const;
  /// Records downloads of the squared gradient magnitudes (CV_32SC1 per level; after a
  /// recordQuantization with `magnitudes`, valid after batch.submit()); images of `out` that
  /// have the right size already are written in place.
  void downloadMagnitudes(Batch& batch, std::vector<cv::Mat>& out) const;

 private:
  struct Level {
    cv::Size size;
    Buffer bgr, blur_rows, smoothed, raw_bins, magnitude, depth_raw;
    Buffer labels[kModalityCount];
    Buffer spread_rows, spread;
    Buffer memory;
    LinearMemoryLayout layout;  // of `memory` as last filled
    int outside_response = 0;   // what the fill left in its padding cells
  };
  struct Kernels;
  const GpuContext& ctx_;
  FeatureParams params_;
  std::unique_ptr<Kernels> kernels_;
  std::vector<Level> levels_;
  Buffer depth_;
};

}  // namespace vkpose::gpu
