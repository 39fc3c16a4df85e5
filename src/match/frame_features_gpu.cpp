#include "match/frame_features_gpu.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>
#include <opencv2/imgproc.hpp>

#include "gpu/kernel_interface.h"
#include "match/match_geometry.hpp"
#include "vkpose/error.hpp"

namespace vkpose::gpu {

namespace {
// Zeros after the last plane, which the similarity kernels may read past (their values
// never reach a score): the coarse pass fetches whole texels up to 64 bytes past a row's last
// position, and refinement units cover 4 rows from a multiple of 4 (up to 3 rows past the
// plane) in blocks that may end up to 31 bytes past a row (counted in bytes per cell: the
// nibbles need half).
std::size_t memoryTailBytes(const LinearMemoryLayout& layout) { return 4 * static_cast<std::size_t>(layout.stride) + 64; }
// A level's linear memory: a nibble per cell (the stride is a multiple of 32 cells).
std::size_t memoryBytes(const LinearMemoryLayout& layout) { return layout.total_bytes() / 2 + memoryTailBytes(layout); }
}  // namespace

struct FrameFeatures::Kernels {
  // Every kernel reads its input (binding 0) through texel fetches, gathers on llvmpipe,
  // where a storage-buffer load at a per-invocation offset is a loop over the lanes: packed
  // words (colour pixels, label images), the row blur's 16-bit sums, 16-bit depth.
  static inline const std::vector<TexelBinding> kWords{{0, vk::Format::eR32Uint}};
  explicit Kernels(const GpuContext& c)
      : blur_rows(c, ShaderId::gaussian_blur7_rows, 2, sizeof(SizePush), {}, kWords),
        blur_cols(c, ShaderId::gaussian_blur7_cols, 2, sizeof(SizePush), {}, {{0, vk::Format::eR32G32Uint}}),
        sobel(c, ShaderId::sobel_orientation, 3, sizeof(SobelPush), {}, kWords),
        vote(c, ShaderId::orientation_vote, 2, sizeof(SizePush), {}, kWords),
        pyr_down(c, ShaderId::pyr_down, 2, sizeof(PyrDownPush), {}, kWords),
        normals(c, ShaderId::depth_normals, 2, sizeof(DepthNormalsPush), {}, {{0, vk::Format::eR16Uint}}),
        median(c, ShaderId::median5, 2, sizeof(SizePush), {}, kWords),
        downsample(c, ShaderId::downsample_labels, 2, sizeof(DownsampleLabelsPush), {}, kWords),
        spread_rows(c, ShaderId::spread_rows, 2, sizeof(SpreadPush), {}, kWords),
        spread(c, ShaderId::spread, 2, sizeof(SpreadPush), {}, kWords),
        linearize(c, ShaderId::response_linearize, 2, sizeof(LinearizePush), {}, kWords) {}
  Kernel blur_rows, blur_cols, sobel, vote, pyr_down, normals, median, downsample, spread_rows, spread, linearize;
};

FrameFeatures::FrameFeatures(const GpuContext& ctx, const FeatureParams& params)
    : ctx_(ctx), params_(params), kernels_(std::make_unique<Kernels>(ctx)) {}

FrameFeatures::~FrameFeatures() = default;

void FrameFeatures::record(Batch& batch, const LinemodFrame& frame, const std::vector<LinearMemoryLayout>& layouts,
                           int outside_response) {
  if (outside_response < 0 || outside_response > 4)
    throw InputError(fmt::format("the response outside the image must be 0..4, not {}", outside_response));
  auto& k = *kernels_;
  const cv::Size full = params_.use_colour ? frame.bgr.size() : frame.depth_mm.size();
  // The linear memories of a level are bound whole (a storage buffer here, a texel buffer in
  // the similarity kernels): a frame whose memories exceed what the device binds at once is
  // refused up front with the size that fits, not by a failing dispatch.
  const auto& dev = ctx_.device();
  const uint64_t bindable = std::min<uint64_t>(dev.max_storage_buffer_range, dev.max_texel_buffer_elements);
  for (std::size_t l = 0; l < layouts.size(); ++l)
    if (layouts[l].total_bytes() > bindable) {
      const double scale = std::sqrt(static_cast<double>(bindable) / static_cast<double>(layouts[l].total_bytes()));
      throw InputError(fmt::format(
          "a {}x{} frame is too large for {}: its response maps at pyramid level {} take {:.0f} MiB, the device binds "
          "at most {:.0f} MiB at once; scale the frame down to about {}x{}",
          full.width, full.height, dev.name, l, static_cast<double>(layouts[l].total_bytes()) / (1 << 20),
          static_cast<double>(bindable) / (1 << 20), static_cast<int>(full.width * scale * 0.98),
          static_cast<int>(full.height * scale * 0.98)));
    }
  recordQuantization(batch, frame, false);
  for (std::size_t l = 0; l < levels_.size(); ++l) {
    Level& L = levels_[l];
    const auto w = static_cast<std::size_t>(L.size.width), h = static_cast<std::size_t>(L.size.height);
    const std::size_t words_per_row = (w + 3) / 4, label_bytes = 4 * words_per_row * h;
    const uint32_t word_groups = groupsFor(words_per_row * h, kWorkgroupSize);
    const uint32_t word_column_groups = groupsFor(words_per_row * ((h + kPixelGroup - 1) / kPixelGroup), kWorkgroupSize);
    // Linear memories: padding cells are never written, so fill the buffer with the response
    // outside the image (a nibble per cell) only when its layout or that response changes.
    const LinearMemoryLayout& layout = layouts[l];
    const bool same = L.layout.T == layout.T && L.layout.width == layout.width && L.layout.height == layout.height &&
                      L.layout.pad == layout.pad && L.layout.stride == layout.stride && L.layout.rows == layout.rows &&
                      L.memory.size() == memoryBytes(layout) && L.outside_response == outside_response;
    if (!same) {
      L.memory = Buffer(ctx_, memoryBytes(layout));
      batch.fill(L.memory, static_cast<uint32_t>(outside_response) * 0x11111111u);
      L.layout = layout;
      L.outside_response = outside_response;
    }
    L.spread.reserve(ctx_, label_bytes);
    L.spread_rows.reserve(ctx_, label_bytes);
    for (int m = 0; m < kModalityCount; ++m) {
      if ((m == 0 && !params_.use_colour) || (m == 1 && !params_.use_depth)) continue;
      const SpreadPush spush{L.size.width, L.size.height, layout.T};
      batch.dispatchLinear(k.spread_rows, {L.labels[m], L.spread_rows}, spush, word_groups);
      batch.dispatchLinear(k.spread, {L.spread_rows, L.spread}, spush, word_column_groups);
      const LinearizePush lpush{L.size.width, L.size.height, layout.T,        layout.pad,
                                layout.stride, layout.rows, outside_response, m};
      // One invocation per 16 aligned padded cells of a pixel row and grid column
      // (response_linearize.comp).
      const int cells_x = (L.size.width + layout.T - 1) / layout.T;
      const auto cell_groups = static_cast<std::size_t>((layout.pad + cells_x + 15) / 16 - layout.pad / 16);
      batch.dispatchLinear(k.linearize, {L.spread, L.memory}, lpush,
                           groupsFor(static_cast<std::size_t>(L.size.height) * static_cast<std::size_t>(layout.T) * cell_groups,
                                     kWorkgroupSize));
    }
  }
}

void FrameFeatures::recordQuantization(Batch& batch, const LinemodFrame& frame, bool magnitudes) {
  auto& k = *kernels_;
  const cv::Size full = params_.use_colour ? frame.bgr.size() : frame.depth_mm.size();
  const auto sizes = match::levelSizes(full.width, full.height, params_.T.size());
  levels_.resize(sizes.size());
  for (std::size_t l = 0; l < sizes.size(); ++l) {
    Level& L = levels_[l];
    L.size = sizes[l];
    const std::size_t n = static_cast<std::size_t>(L.size.area());
    const SizePush sp{L.size.width, L.size.height};
    // Sliding-window kernels take kPixelGroup neighbouring pixels of a row, or of a column,
    // per invocation.
    const auto w = static_cast<std::size_t>(L.size.width), h = static_cast<std::size_t>(L.size.height);
    const uint32_t row_groups = groupsFor(h * ((w + kPixelGroup - 1) / kPixelGroup), kWorkgroupSize);
    const uint32_t column_groups = groupsFor(w * ((h + kPixelGroup - 1) / kPixelGroup), kWorkgroupSize);
    // Label images are packed 4 pixels per word, rows padded to whole words (wordsPerRow in
    // shaders/common.glsl); their kernels take a word per invocation.
    const std::size_t words_per_row = (w + 3) / 4, label_bytes = 4 * words_per_row * h;
    const uint32_t word_groups = groupsFor(words_per_row * h, kWorkgroupSize);

    if (params_.use_colour) {
      // Colour pixels are packed BGRX words on the device (shaders/common.glsl): a word load
      // per pixel instead of a byte load per channel, each being a loop over the lanes on
      // llvmpipe. The frame is converted straight into the staging memory.
      L.bgr.reserve(ctx_, n * 4);
      if (l == 0) {
        cv::Mat bgrx(L.size, CV_8UC4, batch.uploadInPlace(L.bgr, n * 4));
        cv::cvtColor(frame.bgr, bgrx, cv::COLOR_BGR2BGRA);
      } else {
        const Level& P = levels_[l - 1];
        const PyrDownPush push{P.size.width, P.size.height, L.size.width, L.size.height};
        batch.dispatchLinear(k.pyr_down, {P.bgr, L.bgr}, push, row_groups);
      }
      L.blur_rows.reserve(ctx_, n * 8);
      L.smoothed.reserve(ctx_, n * 4);
      L.raw_bins.reserve(ctx_, label_bytes);
      L.labels[0].reserve(ctx_, label_bytes);
      // Frames need no magnitudes: the kernel skips its stores into a placeholder.
      L.magnitude.reserve(ctx_, magnitudes ? n * 4 : 4);
      batch.dispatchLinear(k.blur_rows, {L.bgr, L.blur_rows}, sp, row_groups);
      batch.dispatchLinear(k.blur_cols, {L.blur_rows, L.smoothed}, sp, column_groups);
      const SobelPush sobel_push{L.size.width, L.size.height, params_.weak_threshold * params_.weak_threshold,
                                 magnitudes ? 1 : 0};
      batch.dispatchLinear(k.sobel, {L.smoothed, L.raw_bins, L.magnitude}, sobel_push, word_groups);
      batch.dispatchLinear(k.vote, {L.raw_bins, L.labels[0]}, sp, word_groups);
    }
    if (params_.use_depth) {
      L.labels[1].reserve(ctx_, label_bytes);
      if (l == 0) {
        depth_.reserve(ctx_, n * 2);
        L.depth_raw.reserve(ctx_, label_bytes);
        cv::Mat depth = frame.depth_mm.isContinuous() ? frame.depth_mm : frame.depth_mm.clone();
        batch.upload(depth_, depth.data, n * 2);
        const DepthNormalsPush push{L.size.width, L.size.height, params_.distance_threshold_mm,
                                    params_.difference_threshold_mm};
        batch.dispatchLinear(k.normals, {depth_, L.depth_raw}, push, word_groups);
        batch.dispatchLinear(k.median, {L.depth_raw, L.labels[1]}, sp, word_groups);
      } else {
        const Level& P = levels_[l - 1];
        const DownsampleLabelsPush push{P.size.width, L.size.width, L.size.height};
        batch.dispatchLinear(k.downsample, {P.labels[1], L.labels[1]}, push, word_groups);
      }
    }
  }
}

void FrameFeatures::downloadMagnitudes(Batch& batch, std::vector<cv::Mat>& out) const {
  out.resize(levels_.size());
  for (std::size_t l = 0; l < levels_.size(); ++l) {
    out[l].create(levels_[l].size, CV_32SC1);  // the caller's image when it has this size
    batch.download(levels_[l].magnitude, out[l].data, out[l].total() * 4);
  }
}

void FrameFeatures::downloadLabels(Batch& batch, std::vector<QuantizedLevel>& out) const {
  out.assign(levels_.size(), {});
  for (std::size_t l = 0; l < levels_.size(); ++l) {
    out[l].T = params_.T[l];
    for (int m = 0; m < kModalityCount; ++m) {
      if ((m == 0 && !params_.use_colour) || (m == 1 && !params_.use_depth)) continue;
      // Packed rows of whole words: a view of the padded image, cropped to the width.
      const cv::Size size = levels_[l].size;
      const int pitch = (size.width + 3) / 4 * 4;
      cv::Mat padded(size.height, pitch, CV_8UC1);
      batch.download(levels_[l].labels[m], padded.data, padded.total());
      out[l].labels[m] = padded.colRange(0, size.width);
    }
  }
}

}  // namespace vkpose::gpu
