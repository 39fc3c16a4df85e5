#pragma once
// An RGB-D frame as vkpose reads it, the LINEMOD feature parameters that quantize it (shared
// by training and detection), and files: reading frames, writing images and text.
#include <cstdint>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

namespace vkpose {

/// The two LINEMOD modalities. Each turns its input into a label image: one bit of 8 set per
/// pixel (0 where there is no reliable orientation), so later stages do not care which it was.
enum class Modality : uint8_t { ColourGradient = 0, DepthNormal = 1 };
constexpr int kModalityCount = 2;

struct FeatureParams {
  /// Colour: a pixel keeps its orientation when its squared gradient magnitude (strongest
  /// channel of the 7x7-smoothed image, Sobel 3x3) exceeds weak_threshold^2. OpenCV: 10.
  float weak_threshold = 10.0f;
  /// Depth: pixels at or beyond this distance (mm) get no normal. OpenCV: 2000.
  int distance_threshold_mm = 2000;
  /// Depth: neighbours whose depth differs from the centre by this much (mm) or more are left
  /// out of the least-squares normal. OpenCV: 50.
  int difference_threshold_mm = 50;
  /// Spreading step T per pyramid level, finest first. OpenCV: {5, 8}. One or two levels.
  std::vector<int> T = {5, 8};
  bool use_colour = true;
  bool use_depth = true;
};

/// Throws InputError naming the bad value.
void validateFeatureParams(const FeatureParams& params);

/// An RGB-D frame as LINEMOD reads it: 8-bit BGR colour and 16-bit depth in millimetres
/// (0 = no reading), the same size. Without depth (depth_mm empty) the detector runs colour-only.
struct LinemodFrame {
  cv::Mat bgr;       ///< CV_8UC3
  cv::Mat depth_mm;  ///< CV_16UC1
};

/// Throws InputError when the images are empty, of the wrong type, or of different sizes.
void validateFrame(const LinemodFrame& frame, const FeatureParams& params);

/// Loads a colour PNG/JPEG (8-bit, 3 channels; grey is expanded) and a 16-bit depth PNG.
/// depth_scale: millimetres per depth unit (BOP's `depth_scale`); depth is converted to mm.
/// An empty depth_path reads the colour image alone (a colour-only frame: depth_mm empty).
/// Throws InputError naming the file when one is missing, unreadable, of the wrong bit depth,
/// or when the two differ in size.
LinemodFrame loadFrame(const std::string& rgb_path, const std::string& depth_path, double depth_scale = 1.0);

/// Writes `text` to `path`; InputError when the file exists and `overwrite` is false, or
/// when it cannot be written.
void writeTextFile(const std::string& path, const std::string& text, bool overwrite);

/// Writes an image (PNG); InputError when the file exists and `overwrite` is false, or when
/// it cannot be written.
void writeImage(const std::string& path, const cv::Mat& image, bool overwrite);

}  // namespace vkpose
