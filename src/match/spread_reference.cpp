// Spreading, CPU reference (LINEMOD section 2.3). shaders/spread.comp computes the same bits.
#include "match/features.hpp"

namespace vkpose {

cv::Mat spreadLabels(const cv::Mat& labels, int T) {
  CV_Assert(labels.type() == CV_8UC1 && T >= 1);
  const int w = labels.cols, h = labels.rows;
  cv::Mat out = cv::Mat::zeros(h, w, CV_8UC1);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      uint8_t acc = 0;
      for (int dy = 0; dy < T && y + dy < h; ++dy)
        for (int dx = 0; dx < T && x + dx < w; ++dx) acc |= labels.at<uint8_t>(y + dy, x + dx);
      out.at<uint8_t>(y, x) = acc;
    }
  return out;
}

}  // namespace vkpose
