// The directional chamfer fit of stage 7 without depth (contour_fit.hpp).
#include "pose/contour_fit.hpp"

#include <algorithm>
#include <cmath>

#include <Eigen/Cholesky>
#include <Eigen/Geometry>
#include <opencv2/imgproc.hpp>

#include "vkpose/error.hpp"

namespace vkpose {

int edgeOrientationBin(float dx, float dy) {
  float a = std::atan2(dy, dx);  // -pi..pi
  if (a < 0.f) a += static_cast<float>(M_PI);
  if (a >= static_cast<float>(M_PI)) a -= static_cast<float>(M_PI);
  const int bin = static_cast<int>(std::lround(a / static_cast<float>(M_PI / 8.0)));
  return bin & 7;
}

EdgeDistanceMaps edgeDistanceMaps(const cv::Mat& bgr, double canny_low, double canny_high, bool distances) {
  if (bgr.empty() || bgr.type() != CV_8UC3) throw InputError("edge maps need an 8-bit colour image");
  cv::Mat blurred;
  cv::GaussianBlur(bgr, blurred, {3, 3}, 0);
  // The strongest channel's gradient at each pixel (as LINEMOD's colour modality): an edge
  // between two colours of one brightness is still an edge.
  cv::Mat channels[3];
  cv::split(blurred, channels);
  cv::Mat dx(bgr.size(), CV_16SC1, cv::Scalar(0)), dy(bgr.size(), CV_16SC1, cv::Scalar(0));
  cv::Mat best(bgr.size(), CV_32SC1, cv::Scalar(-1));
  for (const cv::Mat& c : channels) {
    cv::Mat cx, cy;
    cv::Sobel(c, cx, CV_16S, 1, 0, 3);
    cv::Sobel(c, cy, CV_16S, 0, 1, 3);
    for (int y = 0; y < bgr.rows; ++y) {
      const auto* px = cx.ptr<int16_t>(y);
      const auto* py = cy.ptr<int16_t>(y);
      auto* ox = dx.ptr<int16_t>(y);
      auto* oy = dy.ptr<int16_t>(y);
      auto* b = best.ptr<int32_t>(y);
      for (int x = 0; x < bgr.cols; ++x) {
        const int m = px[x] * px[x] + py[x] * py[x];
        if (m > b[x]) b[x] = m, ox[x] = px[x], oy[x] = py[x];
      }
    }
  }
  cv::Mat canny;
  cv::Canny(dx, dy, canny, canny_low, canny_high, true);
  EdgeDistanceMaps maps;
  maps.edges = cv::Mat(bgr.size(), CV_8UC1, cv::Scalar(0));
  // Not-edge masks per bin (distanceTransform measures to the zeros).
  std::array<cv::Mat, 8> free;
  for (auto& f : free) f = cv::Mat(bgr.size(), CV_8UC1, cv::Scalar(255));
  for (int y = 0; y < bgr.rows; ++y)
    for (int x = 0; x < bgr.cols; ++x) {
      if (!canny.at<uint8_t>(y, x)) continue;
      const int bin = edgeOrientationBin(dx.at<int16_t>(y, x), dy.at<int16_t>(y, x));
      maps.edges.at<uint8_t>(y, x) = static_cast<uint8_t>(1 + bin);
      for (int d = -1; d <= 1; ++d) free[static_cast<std::size_t>((bin + d + 8) & 7)].at<uint8_t>(y, x) = 0;
    }
  if (!distances) return maps;
  for (std::size_t b = 0; b < 8; ++b) {
    cv::distanceTransform(free[b], maps.distance[b], cv::DIST_L2, cv::DIST_MASK_PRECISE);
    cv::min(maps.distance[b], kEdgeDistanceCap, maps.distance[b]);
  }
  return maps;
}

namespace {

struct EdgePixel {
  int x, y;
  uint8_t bin;
};

/// The model's edges in a rendering: the mask's border and inner depth steps, then (with
/// `colour_edges`) the edges of the rendered colours inside (see contourPoints).
std::vector<EdgePixel> modelEdgePixels(const Rendering& rendering, float inner_step_m, bool colour_edges = true) {
  const cv::Mat& z = rendering.depth;
  std::vector<EdgePixel> found;
  const auto at = [&](int x, int y) {
    return x < 0 || y < 0 || x >= z.cols || y >= z.rows ? 0.f : z.at<float>(y, x);
  };
  cv::Mat taken(z.size(), CV_8UC1, cv::Scalar(0));
  // The outline's direction from the smoothed mask (the mask's border) or depth (an inner
  // step): a pixel's 4 neighbours alone give multiples of 45 degrees, two bins off an edge
  // at 10 degrees.
  cv::Mat mask_f, mdx, mdy, zdx, zdy;
  cv::Mat(z > 0.f).convertTo(mask_f, CV_32F, 1.0 / 255.0);
  cv::GaussianBlur(mask_f, mask_f, {5, 5}, 1.0);
  cv::Sobel(mask_f, mdx, CV_32F, 1, 0, 3);
  cv::Sobel(mask_f, mdy, CV_32F, 0, 1, 3);
  cv::Sobel(z, zdx, CV_32F, 1, 0, 3);
  cv::Sobel(z, zdy, CV_32F, 0, 1, 3);
  for (int y = 0; y < z.rows; ++y)
    for (int x = 0; x < z.cols; ++x) {
      const float c = at(x, y);
      if (!(c > 0.f)) continue;
      // Where the mask ends, or a farther part of the model begins.
      bool border = false, step = false;
      const int dxs[4] = {1, -1, 0, 0}, dys[4] = {0, 0, 1, -1};
      for (int k = 0; k < 4; ++k) {
        const float o = at(x + dxs[k], y + dys[k]);
        border |= !(o > 0.f);
        step |= o > c + inner_step_m;
      }
      if (!border && !step) continue;
      const float gx = border ? mdx.at<float>(y, x) : zdx.at<float>(y, x);
      const float gy = border ? mdy.at<float>(y, x) : zdy.at<float>(y, x);
      if (gx == 0.f && gy == 0.f) continue;  // a one-pixel sliver: no direction
      found.push_back({x, y, static_cast<uint8_t>(edgeOrientationBin(gx, gy))});
      taken.at<uint8_t>(y, x) = 1;
    }
  // The edges of the model's own colours inside the outline (painted or scanned texture): what
  // tells a view from its silhouette's look-alikes. Two pixels in from the outline, so the
  // border's own gradient is not counted twice.
  if (colour_edges && rendering.bgr.type() == CV_8UC3 && rendering.bgr.size() == z.size() && z.cols >= 8 &&
      z.rows >= 8) {
    const EdgeDistanceMaps own = edgeDistanceMaps(rendering.bgr, 40, 100, false);
    cv::Mat inside = z > 0.f, eroded;
    cv::erode(inside, eroded, cv::Mat(), {-1, -1}, 2);
    for (int y = 0; y < z.rows; ++y)
      for (int x = 0; x < z.cols; ++x) {
        const uint8_t e = own.edges.at<uint8_t>(y, x);
        if (e && eroded.at<uint8_t>(y, x) && !taken.at<uint8_t>(y, x))
          found.push_back({x, y, static_cast<uint8_t>(e - 1)});
      }
  }
  return found;
}

void checkRendering(const Rendering& rendering, const cv::Rect& window) {
  if (rendering.depth.type() != CV_32FC1 || rendering.depth.size() != window.size())
    throw InputError("contour points: the rendering is not the window's size");
}

}  // namespace

std::vector<ContourPoint> contourPoints(const Rendering& rendering, const Pose& pose, const Camera& camera,
                                        const cv::Rect& window, int max_points, float inner_step_m,
                                        bool colour_edges) {
  checkRendering(rendering, window);
  const cv::Mat& z = rendering.depth;
  const std::vector<EdgePixel> found = modelEdgePixels(rendering, inner_step_m, colour_edges);
  std::vector<ContourPoint> points;
  if (found.empty()) return points;
  const std::size_t step = std::max<std::size_t>(1, (found.size() + static_cast<std::size_t>(max_points) - 1) /
                                                        static_cast<std::size_t>(std::max(1, max_points)));
  const Eigen::Matrix3f R_inv = pose.R.transpose();
  for (std::size_t i = 0; i < found.size(); i += step) {
    const EdgePixel& f = found[i];
    const Eigen::Vector3f p = camera.backProject(f.x + window.x, f.y + window.y, z.at<float>(f.y, f.x));
    points.push_back({R_inv * (p - pose.t), f.bin});
  }
  return points;
}

namespace {

/// Bilinear distance and its image gradient at (u, v); false outside the map.
bool sampleDistance(const cv::Mat& d, float u, float v, float& value, float& gu, float& gv) {
  if (!(u >= 1.f && v >= 1.f && u < static_cast<float>(d.cols - 2) && v < static_cast<float>(d.rows - 2))) return false;
  const int x = static_cast<int>(u), y = static_cast<int>(v);
  const float ax = u - static_cast<float>(x), ay = v - static_cast<float>(y);
  const float d00 = d.at<float>(y, x), d01 = d.at<float>(y, x + 1), d10 = d.at<float>(y + 1, x),
              d11 = d.at<float>(y + 1, x + 1);
  value = (1 - ay) * ((1 - ax) * d00 + ax * d01) + ay * ((1 - ax) * d10 + ax * d11);
  gu = (1 - ay) * (d01 - d00) + ay * (d11 - d10);
  gv = (1 - ax) * (d10 - d00) + ax * (d11 - d01);
  return true;
}

struct Cost {
  double sum = 0;
  int inliers = 0, n = 0;
};

/// Truncated squared distances of the points at `pose`; with `H`/`g`, the normal equations
/// of the inliers (twist: translation, then rotation, camera frame, left-multiplied).
Cost evaluate(const std::vector<ContourPoint>& points, const Pose& pose, const Camera& cam, const EdgeDistanceMaps& maps,
              float cap, Eigen::Matrix<double, 6, 6>* H, Eigen::Matrix<double, 6, 1>* g) {
  Cost cost;
  if (H) H->setZero(), g->setZero();
  const double cap2 = static_cast<double>(cap) * cap;
  const FloatIntrinsics k = cam.floatIntrinsics();
  for (const ContourPoint& pt : points) {
    const Eigen::Vector3f p = pose.R * pt.model + pose.t;
    if (!(p.z() > 1e-3f)) continue;
    const Eigen::Vector2f uv = k.project(p);
    float d, gu, gv;
    if (!sampleDistance(maps.distance[pt.bin], uv.x(), uv.y(), d, gu, gv)) continue;  // off the image: no evidence
    ++cost.n;
    if (d >= cap) {
      cost.sum += cap2;
      continue;
    }
    ++cost.inliers;
    cost.sum += static_cast<double>(d) * d;
    if (!H) continue;
    const float iz = 1.f / p.z();
    const Eigen::Vector3f jp(gu * k.fx * iz, gv * k.fy * iz, -(gu * k.fx * p.x() + gv * k.fy * p.y()) * iz * iz);
    Eigen::Matrix<double, 6, 1> J;
    J.head<3>() = jp.cast<double>();
    J.tail<3>() = p.cross(jp).cast<double>();  // d(p)/d(omega) = -[p]x: jp . (omega x p) = omega . (p x jp)
    *H += J * J.transpose();
    *g += J * static_cast<double>(d);
  }
  return cost;
}

Pose applyTwist(const Pose& pose, const Eigen::Matrix<double, 6, 1>& x) {
  const Eigen::Vector3d w = x.tail<3>();
  const double angle = w.norm();
  Eigen::Matrix3f dR = Eigen::Matrix3f::Identity();
  if (angle > 0) dR = Eigen::AngleAxisd(angle, w / angle).toRotationMatrix().cast<float>();
  return {dR * pose.R, dR * pose.t + x.head<3>().cast<float>()};
}

}  // namespace

ContourFit fitContourRound(const std::vector<ContourPoint>& points, const Pose& start, const Camera& camera,
                           const EdgeDistanceMaps& maps, float truncation_px, int iterations) {
  ContourFit fit;
  fit.pose = start;
  Eigen::Matrix<double, 6, 6> H;
  Eigen::Matrix<double, 6, 1> g;
  Cost cost = evaluate(points, fit.pose, camera, maps, truncation_px, &H, &g);
  double lambda = 1e-3;
  for (int it = 0; it < iterations && cost.inliers >= 6; ++it) {
    Eigen::Matrix<double, 6, 6> A = H;
    for (int k = 0; k < 6; ++k) A(k, k) += lambda * std::max(H(k, k), 1e-9);
    const Eigen::Matrix<double, 6, 1> step = A.ldlt().solve(-g);
    if (!step.allFinite()) break;
    const Pose trial = applyTwist(fit.pose, step);
    Eigen::Matrix<double, 6, 6> H2;
    Eigen::Matrix<double, 6, 1> g2;
    const Cost c2 = evaluate(points, trial, camera, maps, truncation_px, &H2, &g2);
    // Compare like with like: a step that pushes points off the image loses their cost.
    const double before = cost.sum / std::max(cost.n, 1), after = c2.sum / std::max(c2.n, 1);
    if (c2.n >= cost.n * 9 / 10 && after < before) {
      fit.pose = trial, cost = c2, H = H2, g = g2;
      lambda = std::max(lambda * 0.3, 1e-6);
      ++fit.iterations;
      if (step.norm() < 1e-5) break;
    } else {
      lambda *= 10;
      if (lambda > 1e4) break;
    }
  }
  fit.mean_distance_px = cost.n ? static_cast<float>(std::sqrt(cost.sum / cost.n)) : truncation_px;
  fit.inliers = cost.n ? static_cast<float>(cost.inliers) / static_cast<float>(cost.n) : 0.f;
  return fit;
}

float explainedEdgeShare(const Rendering& rendering, const cv::Rect& window, const EdgeDistanceMaps& maps,
                         float tolerance_px, float inner_step_m) {
  checkRendering(rendering, window);
  if ((window & cv::Rect({0, 0}, maps.size())) != window) throw InputError("explained edges: the window leaves the frame");
  cv::Mat model(window.size(), CV_8UC1, cv::Scalar(255));
  for (const EdgePixel& e : modelEdgePixels(rendering, inner_step_m)) model.at<uint8_t>(e.y, e.x) = 0;
  cv::Mat distance;
  cv::distanceTransform(model, distance, cv::DIST_L2, cv::DIST_MASK_PRECISE);
  cv::Mat inside = rendering.depth > 0.f;
  const cv::Mat seen = maps.edges(window);
  int total = 0, explained = 0;
  for (int y = 0; y < inside.rows; ++y)
    for (int x = 0; x < inside.cols; ++x) {
      if (!inside.at<uint8_t>(y, x) || !seen.at<uint8_t>(y, x)) continue;
      ++total;
      if (distance.at<float>(y, x) <= tolerance_px) ++explained;
    }
  return total ? static_cast<float>(explained) / static_cast<float>(total) : 1.f;
}

float chamferSupport(const std::vector<ContourPoint>& points, const Pose& pose, const Camera& camera,
                     const EdgeDistanceMaps& maps, float tolerance_px) {
  const Cost c = evaluate(points, pose, camera, maps, tolerance_px, nullptr, nullptr);
  return c.n ? static_cast<float>(c.inliers) / static_cast<float>(c.n) : 0.f;
}

}  // namespace vkpose
