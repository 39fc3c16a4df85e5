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

float regionContrast(const Rendering& rendering, const cv::Rect& window, const cv::Mat& scene_bgr, int band_px) {
  if (scene_bgr.type() != CV_8UC3) throw InputError("regionContrast: the scene must be 8-bit BGR");
  if (rendering.depth.size() != window.size()) throw InputError("regionContrast: the rendering is not the window's size");
  if (band_px < 3) throw InputError("regionContrast: the band must reach at least 3 pixels out");
  // The mask in a canvas grown by the band, so that the band around it fits.
  const int pad = band_px;
  cv::Mat mask(window.height + 2 * pad, window.width + 2 * pad, CV_8U, cv::Scalar(0));
  mask(cv::Rect(pad, pad, window.width, window.height)).setTo(255, rendering.depth > 0.f);
  const auto disc = [](int radius) { return cv::getStructuringElement(cv::MORPH_ELLIPSE, {2 * radius + 1, 2 * radius + 1}); };
  cv::Mat inside, near, band;
  cv::erode(mask, inside, disc(2));  // 2 px off the outline either way: a pose a pixel off
  cv::dilate(mask, near, disc(2));   // would count the other side's colours
  cv::dilate(mask, band, disc(pad));
  band.setTo(0, near);
  constexpr int kLevels = 8, kBins = kLevels * kLevels * kLevels;
  std::vector<float> hist_in(kBins, 0.f), hist_out(kBins, 0.f);
  float n_in = 0.f, n_out = 0.f;
  for (int y = 0; y < mask.rows; ++y) {
    const int sy = y + window.y - pad;
    if (sy < 0 || sy >= scene_bgr.rows) continue;
    for (int x = 0; x < mask.cols; ++x) {
      const int sx = x + window.x - pad;
      if (sx < 0 || sx >= scene_bgr.cols) continue;
      const bool in = inside.at<uint8_t>(y, x) != 0;
      if (!in && !band.at<uint8_t>(y, x)) continue;
      const cv::Vec3b c = scene_bgr.at<cv::Vec3b>(sy, sx);
      const int bin = ((c[0] * kLevels) >> 8) * kLevels * kLevels + ((c[1] * kLevels) >> 8) * kLevels + ((c[2] * kLevels) >> 8);
      (in ? hist_in : hist_out)[static_cast<std::size_t>(bin)] += 1.f;
      (in ? n_in : n_out) += 1.f;
    }
  }
  if (n_in < kMinColourPixels || n_out < kMinColourPixels) return 0.f;
  // Each bin goes to the side where its colour is the more frequent, the frequencies smoothed
  // by half a pixel a bin so that a colour one side lacks does not decide alone; each side's
  // pixels in the bins it gets are the ones it claims.
  const float smoothed_in = n_in + 0.5f * kBins, smoothed_out = n_out + 0.5f * kBins;
  float own_in = 0.f, own_out = 0.f;
  for (std::size_t b = 0; b < hist_in.size(); ++b) {
    if ((hist_in[b] + 0.5f) / smoothed_in > (hist_out[b] + 0.5f) / smoothed_out)
      own_in += hist_in[b];
    else
      own_out += hist_out[b];
  }
  return own_in / n_in + own_out / n_out - 1.f;
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
