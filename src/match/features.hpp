#pragma once
// Stage 1, frame features (Hinterstoisser et al., LINEMOD, PAMI 2012, sections 2.2-2.6):
// quantized colour-gradient and depth-normal orientations, spreading, response maps and
// linearized memories, for every pyramid level. These are the plain C++ reference
// implementations; shaders/ holds the GPU kernels that compute the same bits.
#include <array>
#include <cstdint>
#include <vector>

#include <opencv2/core.hpp>

#include "vkpose/frame.hpp"

namespace vkpose {

// ---- colour gradient modality (section 2.2) -------------------------------------------

/// 7x7 Gaussian (binomial weights 8,28,56,72,56,28,8 / 256 per axis, fixed point, replicated
/// border), bit-exact with OpenCV's GaussianBlur(7x7, sigma 0) on 8-bit images.
cv::Mat gaussianBlur7(const cv::Mat& bgr);

/// Orientation bin 0..7 of a gradient (gx, gy), sign ignored: bin k is centred on k * 22.5
/// degrees. Decided with exact integer comparisons against tangent thresholds (no atan), so
/// CPU and GPU agree bit for bit. Valid for |gx|, |gy| <= 1020 (Sobel of 8-bit data).
int gradientOrientationBin(int gx, int gy);

/// Sobel per channel of the smoothed image, strongest channel, orientation bin, 3x3
/// majority vote (>= 5 of 9) among pixels whose squared magnitude exceeds weak^2.
/// Output: CV_8UC1 label image (1 << bin, or 0). `magnitude_sq`, when given, receives the
/// squared gradient magnitude of the strongest channel (CV_32SC1), which training ranks by.
cv::Mat quantizeColourGradients(const cv::Mat& bgr, float weak_threshold, cv::Mat* magnitude_sq = nullptr);

/// Next pyramid level of the colour image: 5x5 binomial, every second pixel, reflected
/// border (bit-exact with cv::pyrDown to (cols / 2, rows / 2)).
cv::Mat pyrDownColour(const cv::Mat& bgr);

// ---- depth normal modality (section 2.6) ----------------------------------------------

/// Orientation bin 0..7 of a depth normal from LINEMOD's least-squares depth gradient
/// (ddx, ddy): bin k is centred on k * 45 degrees in the image plane.
int normalOrientationBin(int ddx, int ddy);

/// LINEMOD's fast least-squares normals (8 neighbours 5 px away, skipping those that differ
/// by difference_threshold or more), binned into 8 directions, then a 5x5 median.
/// Output: CV_8UC1 label image.
cv::Mat quantizeDepthNormals(const cv::Mat& depth_mm, int distance_threshold_mm, int difference_threshold_mm);

/// Nearest-neighbour halving of a label image (pixel (2x, 2y)), size (cols / 2, rows / 2).
cv::Mat downsampleLabels(const cv::Mat& labels);

// ---- spreading, response maps, linear memories (sections 2.3-2.5) ---------------------

/// OR of the labels in the T x T window below and to the right of each pixel (LINEMOD's
/// spreading; the match position convention compensates for the one-sided window).
cv::Mat spreadLabels(const cv::Mat& labels, int T);

/// Response of orientation `bin` to a spread label set: 4 - (circular distance, in bins, to
/// the nearest orientation in the set); 0 for an empty set. A quantized cosine.
int responseFor(int bin, uint8_t spread_labels);

/// The 8 response maps (CV_8UC1, one per orientation bin) of a spread label image.
std::array<cv::Mat, 8> computeResponseMaps(const cv::Mat& spread);

/// Geometry of one pyramid level's linear memories. The response maps are stored per
/// modality, per orientation bin and per (y mod T, x mod T) "grid" as 2D planes of cells
/// (pixel / T), padded with zero cells on every side so that templates partly outside the
/// image read zeros instead of wrapping around (OpenCV wraps, and loses the top/left border).
/// Sizes and offsets count cells: a byte each in the CPU reference, a nibble each on the GPU.
struct LinearMemoryLayout {
  int T = 0;
  int width = 0, height = 0;              ///< image size at this level, pixels
  int cells_x = 0, cells_y = 0;           ///< ceil(width / T), ceil(height / T)
  int pad = 0;                            ///< zero cells left of and above the image
  int stride = 0;                         ///< cells per padded row (a multiple of 32)
  int rows = 0;                           ///< padded rows per plane
  std::size_t plane_bytes() const { return static_cast<std::size_t>(stride) * rows; }
  std::size_t modality_bytes() const { return plane_bytes() * 8 * T * T; }
  std::size_t total_bytes() const { return modality_bytes() * kModalityCount; }
  /// Byte offset of cell (cell_y, cell_x) (image cells, may be negative down to -pad) of
  /// grid (gy, gx) of `bin` of `modality`.
  std::size_t offset(int modality, int bin, int gy, int gx, int cell_y, int cell_x) const {
    return static_cast<std::size_t>(((modality * 8 + bin) * T + gy) * T + gx) * plane_bytes() +
           static_cast<std::size_t>(cell_y + pad) * stride + static_cast<std::size_t>(cell_x + pad);
  }
};

/// A layout for a level of `width` x `height` pixels whose templates span at most
/// `max_template_cells` cells in x or y; `extra_cells` more margin for local refinement.
LinearMemoryLayout makeLinearMemoryLayout(int width, int height, int T, int max_template_cells, int extra_cells);

/// Writes the 8 response maps of `modality` into `memory` (layout.total_bytes(), filled by
/// the caller with the response of cells outside the image, MatchParams::outside_response)
/// in the linearized order of `layout`.
void linearizeResponseMaps(const std::array<cv::Mat, 8>& response_maps, int modality,
                           const LinearMemoryLayout& layout, std::vector<uint8_t>& memory);

/// The label images of one pyramid level (empty Mat for a modality that is off).
struct QuantizedLevel {
  cv::Mat labels[kModalityCount];
  int T = 0;
};

/// Stage 1 on the CPU for every level: the reference the GPU kernels are tested against.
std::vector<QuantizedLevel> quantizeFramePyramid(const LinemodFrame& frame, const FeatureParams& params);

}  // namespace vkpose
