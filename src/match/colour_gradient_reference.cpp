// Colour gradient modality, CPU reference (LINEMOD section 2.2). shaders/gaussian_blur7_*.comp,
// sobel_orientation.comp, orientation_vote.comp and pyr_down.comp compute the same bits.
#include <algorithm>

#include "match/border.hpp"
#include "match/features.hpp"

namespace vkpose {
namespace {

// Binomial 7-tap kernel in 8.8 fixed point: what OpenCV's bit-exact GaussianBlur uses for
// ksize 7, sigma 0 (the table [1 3.5 7 9 7 3.5 1] / 32 scaled by 256).
constexpr int kGauss7[7] = {8, 28, 56, 72, 56, 28, 8};

// Orientation bin edges at 11.25, 33.75, 56.25 and 78.75 degrees as tan(edge) * 2^19,
// rounded. For |gx|, |gy| <= 1020 the comparisons gy * 2^19 >= |gx| * kTan[i] decide every
// integer pair exactly (tests/match/orientation_bins_test.cpp checks all of them).
constexpr uint32_t kTanEdge[4] = {104287u, 350318u, 784652u, 2635774u};

}  // namespace

cv::Mat gaussianBlur7(const cv::Mat& bgr) {
  CV_Assert(bgr.type() == CV_8UC3);
  const int w = bgr.cols, h = bgr.rows;
  cv::Mat rows(h, w, CV_16UC3), out(h, w, CV_8UC3);
  for (int y = 0; y < h; ++y) {
    const uint8_t* s = bgr.ptr<uint8_t>(y);
    uint16_t* r = rows.ptr<uint16_t>(y);
    for (int x = 0; x < w; ++x)
      for (int ch = 0; ch < 3; ++ch) {
        uint32_t acc = 0;
        for (int i = 0; i < 7; ++i) acc += kGauss7[i] * s[clampIndex(x + i - 3, w) * 3 + ch];
        r[x * 3 + ch] = static_cast<uint16_t>(acc);
      }
  }
  for (int y = 0; y < h; ++y) {
    uint8_t* o = out.ptr<uint8_t>(y);
    for (int x = 0; x < w * 3; ++x) {
      uint32_t acc = 0;
      for (int j = 0; j < 7; ++j) acc += kGauss7[j] * rows.ptr<uint16_t>(clampIndex(y + j - 3, h))[x];
      o[x] = static_cast<uint8_t>((acc + (1u << 15)) >> 16);
    }
  }
  return out;
}

int gradientOrientationBin(int gx, int gy) {
  if (gy == 0) return 0;  // includes no gradient at all: atan2(0, 0) = 0 in OpenCV
  // Fold to [0, 180): the sign of a gradient carries no information (section 2.2).
  if (gy < 0 || (gy == 0 && gx < 0)) {
    gx = -gx;
    gy = -gy;
  }
  const uint32_t ax = static_cast<uint32_t>(gx < 0 ? -gx : gx);
  const uint32_t sy = static_cast<uint32_t>(gy) << 19;
  int b = 0;
  for (uint32_t t : kTanEdge) b += sy >= ax * t ? 1 : 0;
  return gx >= 0 ? b : (8 - b) & 7;
}

cv::Mat quantizeColourGradients(const cv::Mat& bgr, float weak_threshold, cv::Mat* magnitude_sq) {
  const cv::Mat smoothed = gaussianBlur7(bgr);
  const int w = bgr.cols, h = bgr.rows;
  cv::Mat raw_bins = cv::Mat::zeros(h, w, CV_8UC1);
  cv::Mat magnitude = cv::Mat::zeros(h, w, CV_32SC1);
  for (int y = 0; y < h; ++y) {
    const uint8_t* up = smoothed.ptr<uint8_t>(clampIndex(y - 1, h));
    const uint8_t* mid = smoothed.ptr<uint8_t>(y);
    const uint8_t* down = smoothed.ptr<uint8_t>(clampIndex(y + 1, h));
    for (int x = 0; x < w; ++x) {
      const int l = clampIndex(x - 1, w) * 3, r = clampIndex(x + 1, w) * 3, c = x * 3;
      int best_gx = 0, best_gy = 0, best_mag = -1;
      for (int ch = 0; ch < 3; ++ch) {
        const int gx = (up[r + ch] + 2 * mid[r + ch] + down[r + ch]) - (up[l + ch] + 2 * mid[l + ch] + down[l + ch]);
        const int gy = (down[l + ch] + 2 * down[c + ch] + down[r + ch]) - (up[l + ch] + 2 * up[c + ch] + up[r + ch]);
        const int mag = gx * gx + gy * gy;
        // Strongest channel; ties go to the earlier channel, as in OpenCV.
        if (mag > best_mag) {
          best_mag = mag;
          best_gx = gx;
          best_gy = gy;
        }
      }
      magnitude.at<int32_t>(y, x) = best_mag;
      // The outermost rows and columns vote for bin 0, as in OpenCV.
      const bool border = x == 0 || y == 0 || x == w - 1 || y == h - 1;
      raw_bins.at<uint8_t>(y, x) = border ? 0 : static_cast<uint8_t>(gradientOrientationBin(best_gx, best_gy));
    }
  }
  const float threshold_sq = weak_threshold * weak_threshold;
  cv::Mat labels = cv::Mat::zeros(h, w, CV_8UC1);
  for (int y = 1; y < h - 1; ++y)
    for (int x = 1; x < w - 1; ++x) {
      if (!(static_cast<float>(magnitude.at<int32_t>(y, x)) > threshold_sq)) continue;
      int histogram[8] = {0, 0, 0, 0, 0, 0, 0, 0};
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) histogram[raw_bins.at<uint8_t>(y + dy, x + dx)]++;
      int best = 0;
      for (int i = 1; i < 8; ++i)
        if (histogram[i] > histogram[best]) best = i;
      if (histogram[best] >= 5) labels.at<uint8_t>(y, x) = static_cast<uint8_t>(1u << best);
    }
  if (magnitude_sq) *magnitude_sq = magnitude;
  return labels;
}

cv::Mat pyrDownColour(const cv::Mat& bgr) {
  CV_Assert(bgr.type() == CV_8UC3);
  static constexpr int k[5] = {1, 4, 6, 4, 1};
  const int w = bgr.cols, h = bgr.rows, dw = w / 2, dh = h / 2;
  cv::Mat out(dh, dw, CV_8UC3);
  for (int y = 0; y < dh; ++y)
    for (int x = 0; x < dw; ++x)
      for (int ch = 0; ch < 3; ++ch) {
        int acc = 0;
        for (int j = 0; j < 5; ++j) {
          const uint8_t* row = bgr.ptr<uint8_t>(reflect101Index(2 * y + j - 2, h));
          int racc = 0;
          for (int i = 0; i < 5; ++i) racc += k[i] * row[reflect101Index(2 * x + i - 2, w) * 3 + ch];
          acc += k[j] * racc;
        }
        out.ptr<uint8_t>(y)[x * 3 + ch] = static_cast<uint8_t>((acc + 128) >> 8);
      }
  return out;
}

}  // namespace vkpose
