// Render and compare for near-symmetric poses (appearance.hpp).
#include "pose/appearance.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include <opencv2/imgproc.hpp>

#include "vkpose/error.hpp"

namespace vkpose {

namespace {

/// Below this r+g+b (of 765) a pixel's chromaticity is mostly noise: shadows, dark paint.
constexpr int kMinBrightness = 60;
/// Fewer pixels with a chromaticity than this: too few to say anything about colour.
constexpr int kMinColourPixels = 20;

bool chroma(const cv::Vec3b& bgr, double& r, double& g) {
  const int sum = bgr[0] + bgr[1] + bgr[2];
  if (sum < kMinBrightness) return false;
  r = bgr[2] / static_cast<double>(sum);
  g = bgr[1] / static_cast<double>(sum);
  return true;
}

/// The standard deviation of n (r, g) chromaticities from their sums and sum of squares.
double chromaSpread(double n, double sr, double sg, double ss) {
  return std::sqrt(std::max(0.0, ss / n - (sr * sr + sg * sg) / (n * n)));
}

}  // namespace

double meshChromaSpread(const Mesh& mesh) {
  if (mesh.colours.empty()) return 0.0;
  double n = 0, sr = 0, sg = 0, ss = 0;
  for (const Eigen::Vector3f& c : mesh.colours) {
    const double sum = static_cast<double>(c.x()) + c.y() + c.z();
    if (sum < kMinBrightness / 255.0) continue;
    const double r = c.x() / sum, g = c.y() / sum;
    n += 1, sr += r, sg += g, ss += r * r + g * g;
  }
  if (n < 2) return 0.0;
  return chromaSpread(n, sr, sg, ss);
}

double seenChromaSpread(const Rendering& rendering, const cv::Rect& window, const cv::Mat& scene_bgr) {
  if (scene_bgr.type() != CV_8UC3) throw InputError("seenChromaSpread: the scene must be 8-bit BGR");
  if (rendering.depth.size() != window.size()) throw InputError("seenChromaSpread: the rendering is not the window's size");
  cv::Mat inside = rendering.depth > 0.f;
  cv::erode(inside, inside, cv::getStructuringElement(cv::MORPH_ELLIPSE, {5, 5}));
  double n = 0, sr = 0, sg = 0, ss = 0;
  for (int y = 0; y < window.height; ++y) {
    const int sy = y + window.y;
    if (sy < 0 || sy >= scene_bgr.rows) continue;
    for (int x = 0; x < window.width; ++x) {
      const int sx = x + window.x;
      double r, g;
      if (sx < 0 || sx >= scene_bgr.cols || !inside.at<uint8_t>(y, x) || !chroma(scene_bgr.at<cv::Vec3b>(sy, sx), r, g))
        continue;
      n += 1, sr += r, sg += g, ss += r * r + g * g;
    }
  }
  if (n < kMinColourPixels) return std::numeric_limits<double>::quiet_NaN();
  return chromaSpread(n, sr, sg, ss);
}

AppearanceAgreement appearanceAgreement(const Rendering& rendering, const cv::Rect& window, const cv::Mat& scene_bgr,
                                        const cv::Mat& scene_depth_m, float depth_tolerance, bool colour_counts) {
  if (scene_bgr.type() != CV_8UC3 || scene_depth_m.type() != CV_32FC1 || scene_bgr.size() != scene_depth_m.size())
    throw InputError("appearanceAgreement: colour and depth must be 8-bit BGR and float depth of one size");
  if (rendering.depth.size() != window.size() || rendering.bgr.size() != window.size())
    throw InputError("appearanceAgreement: the rendering is not the window's size");
  AppearanceAgreement out;
  int fits = 0;
  double residual = 0;
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
      residual += std::min(std::abs(sz - rz), depth_tolerance);
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
  out.depth_residual_m = static_cast<float>(residual / out.pixels);
  out.score = out.depth_fit;
  if (!colour_counts || n < kMinColourPixels) return out;
  const double var_a = saa / n - (sa_r * sa_r + sa_g * sa_g) / (n * n);
  const double var_b = sbb / n - (sb_r * sb_r + sb_g * sb_g) / (n * n);
  const double cov = sab / n - (sa_r * sb_r + sa_g * sb_g) / (n * n);
  const double dr = (sa_r - sb_r) / n, dg = (sa_g - sb_g) / n;
  // Lin's concordance, leaning on the means only where the rendering is of about one colour
  // (weight w): there the mean is all that can tell one painted face from another, and a
  // floor makes two single colours that agree score near 1 rather than 0/0. Where the
  // rendering's colours vary, w fades and what is left is about a correlation: blind to a
  // tinted light, and near 0 for a plain look-alike.
  const double base = kMinChromaSpread * kMinChromaSpread;
  const double w = base / (base + std::max(0.0, var_a));
  out.colour_informative = true;
  out.colour = static_cast<float>((2.0 * cov + w * base) / (var_a + var_b + w * (dr * dr + dg * dg) + w * base));
  out.score = out.depth_fit * 0.5f * (1.f + out.colour);
  return out;
}

}  // namespace vkpose
