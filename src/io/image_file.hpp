#pragma once
// Reading and writing image files. Two implementations, picked by CMake's VKPOSE_LIBPNG_IMAGES:
// OpenCV's imgcodecs (image_file_opencv.cpp, the default) and libpng alone
// (image_file_png.cpp, PNG only) for builds that must not pull imgcodecs' ~140 shared
// libraries (GDAL, the video codecs, ICU, ...): the GPU bundle of scripts/gpu-bundle.sh.
#include <string>

#include <opencv2/core.hpp>

namespace vkpose {

enum class ImageChannels {
  AsStored,  ///< as cv::imread's IMREAD_UNCHANGED: the file's channels (BGR order) and bit depth
  Grey,      ///< as IMREAD_ANYDEPTH: one channel, 8 or 16 bits as stored
};

/// The image in `path`; an empty Mat when it cannot be decoded, with `why` set when the
/// decoder said why.
cv::Mat readImageFile(const std::string& path, ImageChannels channels, std::string& why);

/// Writes `image` (8 or 16 bits, 1, 3 or 4 channels, BGR order) to `path` in the format its
/// extension names. False when it cannot (an unknown extension, no such folder); `why` is set
/// when the encoder said why.
bool writeImageFile(const std::string& path, const cv::Mat& image, std::string& why);

}  // namespace vkpose
