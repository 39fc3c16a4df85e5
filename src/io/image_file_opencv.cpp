// Image files through OpenCV's imgcodecs (the default; see image_file.hpp).
#include <opencv2/imgcodecs.hpp>

#include "io/image_file.hpp"

namespace vkpose {

cv::Mat readImageFile(const std::string& path, ImageChannels channels, std::string& why) {
  try {
    return cv::imread(path, channels == ImageChannels::Grey ? cv::IMREAD_ANYDEPTH : cv::IMREAD_UNCHANGED);
  } catch (const cv::Exception& e) {
    why = e.what();
    return {};
  }
}

bool writeImageFile(const std::string& path, const cv::Mat& image, std::string& why) {
  try {
    return cv::imwrite(path, image);
  } catch (const cv::Exception& e) {
    why = e.what();
    return false;
  }
}

}  // namespace vkpose
