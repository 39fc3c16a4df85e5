#include <cmath>
#include <filesystem>

#include <opencv2/imgproc.hpp>

#include "io/image_file.hpp"
#include "vkpose/error.hpp"
#include "vkpose/frame.hpp"

namespace vkpose {

namespace {
cv::Mat readImage(const std::string& path, ImageChannels channels, const char* what) {
  if (!std::filesystem::exists(path)) throw InputError(std::string(what) + " image '" + path + "' does not exist");
  std::string why;
  const cv::Mat m = readImageFile(path, channels, why);
  if (!why.empty()) throw InputError(std::string(what) + " image '" + path + "' cannot be read: " + why);
  if (m.empty()) throw InputError(std::string(what) + " image '" + path + "' is empty or not an image");
  return m;
}
}  // namespace

LinemodFrame loadFrame(const std::string& rgb_path, const std::string& depth_path, double depth_scale) {
  if (!(depth_scale > 0.0) || !std::isfinite(depth_scale))
    throw InputError("depth scale " + std::to_string(depth_scale) + " must be a positive number (mm per unit)");
  LinemodFrame f;
  cv::Mat colour = readImage(rgb_path, ImageChannels::AsStored, "colour");
  if (colour.depth() != CV_8U)
    throw InputError("colour image '" + rgb_path + "' must have 8 bits per channel");
  if (colour.channels() == 1) cv::cvtColor(colour, colour, cv::COLOR_GRAY2BGR);
  else if (colour.channels() == 4) cv::cvtColor(colour, colour, cv::COLOR_BGRA2BGR);
  else if (colour.channels() != 3) throw InputError("colour image '" + rgb_path + "' has an unsupported channel count");
  f.bgr = colour;
  if (depth_path.empty()) return f;  // colour only
  cv::Mat depth = readImage(depth_path, ImageChannels::Grey, "depth");
  if (depth.type() != CV_16UC1)
    throw InputError("depth image '" + depth_path + "' must be a 16-bit single-channel PNG");
  if (depth_scale != 1.0) depth.convertTo(depth, CV_16U, depth_scale);
  f.depth_mm = depth;
  if (f.bgr.size() != f.depth_mm.size())
    throw InputError("colour '" + rgb_path + "' (" + std::to_string(f.bgr.cols) + "x" + std::to_string(f.bgr.rows) +
                     ") and depth '" + depth_path + "' (" + std::to_string(f.depth_mm.cols) + "x" +
                     std::to_string(f.depth_mm.rows) + ") differ in size");
  return f;
}

}  // namespace vkpose
