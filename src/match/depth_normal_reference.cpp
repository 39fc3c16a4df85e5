// Depth normal modality, CPU reference (LINEMOD section 2.6). shaders/depth_normals.comp,
// median5.comp and downsample_labels.comp compute the same bits.
#include <algorithm>
#include <cstdlib>

#include "match/border.hpp"
#include "match/features.hpp"

namespace vkpose {

int normalOrientationBin(int ddx, int ddy) {
  // Sector of the normal's image-plane direction, 45 degrees wide, centred on k * 45 degrees.
  // Edges at 22.5 and 67.5 degrees: float products of exact integers, identical on the GPU.
  if (ddx == 0 && ddy == 0) return 0;  // facing the camera: bin 0, as OpenCV's table
  const float ax = static_cast<float>(std::abs(ddx)), ay = static_cast<float>(std::abs(ddy));
  const int b = (ay >= ax * 0.41421356f ? 1 : 0) + (ay >= ax * 2.41421356f ? 1 : 0);
  if (ddx >= 0) return ddy >= 0 ? b : (8 - b) & 7;
  return ddy >= 0 ? 4 - b : 4 + b;
}

cv::Mat quantizeDepthNormals(const cv::Mat& depth_mm, int distance_threshold_mm, int difference_threshold_mm) {
  CV_Assert(depth_mm.type() == CV_16UC1);
  const int w = depth_mm.cols, h = depth_mm.rows;
  constexpr int r = 5;  // neighbour distance in pixels (OpenCV's l_r)
  cv::Mat raw = cv::Mat::zeros(h, w, CV_8UC1);
  for (int y = r; y < h - r - 1; ++y)
    for (int x = r; x < w - r - 1; ++x) {
      const int d = depth_mm.at<uint16_t>(y, x);
      if (d >= distance_threshold_mm) continue;
      int a0 = 0, a1 = 0, a3 = 0, b0 = 0, b1 = 0;
      for (int j = -r; j <= r; j += r)
        for (int i = -r; i <= r; i += r) {
          if (i == 0 && j == 0) continue;
          const int delta = depth_mm.at<uint16_t>(y + j, x + i) - d;
          if (std::abs(delta) >= difference_threshold_mm) continue;
          a0 += i * i;
          a1 += i * j;
          a3 += j * j;
          b0 += i * delta;
          b1 += j * delta;
        }
      const int det = a0 * a3 - a1 * a1;
      const int ddx = a3 * b0 - a1 * b1;
      const int ddy = -a1 * b0 + a0 * b1;
      // No normal where the fit is empty (a shadow, or no valid neighbour).
      if (ddx == 0 && ddy == 0 && det * d == 0) continue;
      raw.at<uint8_t>(y, x) = static_cast<uint8_t>(1u << normalOrientationBin(ddx, ddy));
    }
  // 5x5 median of the label values (replicated border), as OpenCV's medianBlur(5).
  cv::Mat out(h, w, CV_8UC1);
  uint8_t window[25];
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      int n = 0;
      for (int dy = -2; dy <= 2; ++dy)
        for (int dx = -2; dx <= 2; ++dx) window[n++] = raw.at<uint8_t>(clampIndex(y + dy, h), clampIndex(x + dx, w));
      std::nth_element(window, window + 12, window + 25);
      out.at<uint8_t>(y, x) = window[12];
    }
  return out;
}

cv::Mat downsampleLabels(const cv::Mat& labels) {
  CV_Assert(labels.type() == CV_8UC1);
  cv::Mat out(labels.rows / 2, labels.cols / 2, CV_8UC1);
  for (int y = 0; y < out.rows; ++y)
    for (int x = 0; x < out.cols; ++x) out.at<uint8_t>(y, x) = labels.at<uint8_t>(2 * y, 2 * x);
  return out;
}

}  // namespace vkpose
