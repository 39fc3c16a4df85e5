// Render and compare for near-symmetric poses (appearance.hpp).
#include "pose/appearance.hpp"

#include <cmath>

#include "vkpose/error.hpp"

namespace vkpose {

namespace {

/// Below this r+g+b (of 765) a pixel's chromaticity is mostly noise: shadows, dark paint.
constexpr int kMinBrightness = 60;
/// A rendering whose chromaticity varies less than this (standard deviation) has no colour
/// to compare: an uncoloured mesh renders grey.
constexpr double kMinChromaSpread = 0.05;

bool chroma(const cv::Vec3b& bgr, double& r, double& g) {
  const int sum = bgr[0] + bgr[1] + bgr[2];
  if (sum < kMinBrightness) return false;
  r = bgr[2] / static_cast<double>(sum);
  g = bgr[1] / static_cast<double>(sum);
  return true;
}

}  // namespace

AppearanceAgreement appearanceAgreement(const Rendering& rendering, const cv::Rect& window, const cv::Mat& scene_bgr,
                                        const cv::Mat& scene_depth_m, float depth_tolerance) {
  if (scene_bgr.type() != CV_8UC3 || scene_depth_m.type() != CV_32FC1 || scene_bgr.size() != scene_depth_m.size())
    throw InputError("appearanceAgreement: colour and depth must be 8-bit BGR and float depth of one size");
  if (rendering.depth.size() != window.size() || rendering.bgr.size() != window.size())
    throw InputError("appearanceAgreement: the rendering is not the window's size");
  AppearanceAgreement out;
  int fits = 0;
  // Sums for the correlation of the 2-vectors (r, g) rendered against seen.
  double n = 0, sa_r = 0, sa_g = 0, sb_r = 0, sb_g = 0, saa = 0, sbb = 0, sab = 0;
  for (int y = 0; y < window.height; ++y) {
    const int sy = y + window.y;
    if (sy < 0 || sy >= scene_bgr.rows) continue;
    for (int x = 0; x < window.width; ++x) {
      const int sx = x + window.x;
      if (sx < 0 || sx >= scene_bgr.cols) continue;
      const float rz = rendering.depth.at<float>(y, x), sz = scene_depth_m.at<float>(sy, sx);
      if (rz <= 0.f || sz <= 0.f || sz < rz - depth_tolerance) continue;  // not the object, no depth, hidden
      ++out.pixels;
      if (sz > rz + depth_tolerance) continue;  // seen through
      ++fits;
      double ar, ag, br, bg;
      if (!chroma(rendering.bgr.at<cv::Vec3b>(y, x), ar, ag) || !chroma(scene_bgr.at<cv::Vec3b>(sy, sx), br, bg))
        continue;
      n += 1;
      sa_r += ar, sa_g += ag, sb_r += br, sb_g += bg;
      saa += ar * ar + ag * ag, sbb += br * br + bg * bg, sab += ar * br + ag * bg;
    }
  }
  if (out.pixels == 0) return out;
  out.depth_fit = static_cast<float>(fits) / static_cast<float>(out.pixels);
  out.score = out.depth_fit;
  if (n < 2) return out;
  const double var_a = saa / n - (sa_r * sa_r + sa_g * sa_g) / (n * n);
  const double var_b = sbb / n - (sb_r * sb_r + sb_g * sb_g) / (n * n);
  const double cov = sab / n - (sa_r * sb_r + sa_g * sb_g) / (n * n);
  if (var_a < kMinChromaSpread * kMinChromaSpread) return out;
  out.colour_informative = true;
  out.colour = var_b > 1e-12 ? static_cast<float>(cov / std::sqrt(var_a * var_b)) : 0.f;
  out.score = out.depth_fit * 0.5f * (1.f + out.colour);
  return out;
}

}  // namespace vkpose
