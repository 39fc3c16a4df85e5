#pragma once
// Training's feature quantization on the GPU: the crops of many rendered views packed into one
// image (an atlas) and run through the frame-feature kernels (shaders/, the same bits as
// features.hpp), so that a batch of views costs a few dispatches instead of a CPU filter pass
// each.
#include <memory>
#include <vector>

#include "training/training.hpp"
#include "vkpose/device.hpp"
#include "vkpose/frame.hpp"

namespace vkpose {

namespace gpu {
class Batch;
class FrameFeatures;
}  // namespace gpu

class ViewQuantizer {
 public:
  /// `max_atlas_pixels`: the size of one atlas image at most (level 0); more crops go into
  /// further atlases, one submit each.
  ViewQuantizer(const GpuContext& ctx, const FeatureParams& params, std::size_t max_atlas_pixels = kAtlasPixels);
  ~ViewQuantizer();
  ViewQuantizer(const ViewQuantizer&) = delete;
  ViewQuantizer& operator=(const ViewQuantizer&) = delete;

  /// quantizeView of every crop (bgr CV_8UC3 and depth_mm CV_16UC1 of one size each), bit for
  /// bit, provided each crop's outer pixels are background (zero depth, black), as a rendering
  /// cropped by featureCrop is: crops are packed kGap zero pixels apart, and a filter reaching
  /// over a crop's edge then sees zeros, as the CPU's replicated border of a zero edge.
  std::vector<QuantizedView> quantize(const std::vector<LinemodFrame>& crops);

  /// About 30 bytes of device memory per atlas pixel.
  static constexpr std::size_t kAtlasPixels = std::size_t{6} << 20;
  /// Zero pixels between crops. A pixel's label and magnitude depend on the image up to 19
  /// level-0 pixels away (level 1's pyramid, blur, Sobel and vote), and the labels training
  /// reads lie within 8 pixels of the object's box, so another crop's object must stay 27
  /// pixels away: crops hold at least 12 pixels of background on every side (featureCrop's
  /// margin, or the tile's where its edge cuts the crop), and 12 + 4 + 12 = 28.
  static constexpr int kGap = 4;

 private:
  FeatureParams params_;
  std::size_t max_atlas_pixels_;
  std::unique_ptr<gpu::Batch> batch_;
  std::unique_ptr<gpu::FrameFeatures> features_;
  LinemodFrame atlas_;               ///< the atlas images, kept from call to call
  std::vector<cv::Mat> magnitudes_;  ///< downloads, likewise
};

}  // namespace vkpose
