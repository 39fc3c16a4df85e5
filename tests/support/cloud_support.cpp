#include "cloud_support.hpp"

#include <algorithm>
#include <cmath>

#include <Eigen/Geometry>
#include <opencv2/imgproc.hpp>

namespace vkpose::test {
namespace {

Eigen::Vector3f pixelPoint(const Camera& c, int x, int y, float z) {
  return {static_cast<float>((x - c.cx) * z / c.fx), static_cast<float>((y - c.cy) * z / c.fy), z};
}

template <class T, class ToMetres>
PointCloud backProjectAny(const cv::Mat& depth, const Camera& camera, cv::Rect roi, ToMetres metres) {
  if (roi.empty()) roi = {0, 0, depth.cols, depth.rows};
  roi &= cv::Rect(0, 0, depth.cols, depth.rows);
  PointCloud points;
  for (int y = roi.y; y < roi.y + roi.height; ++y)
    for (int x = roi.x; x < roi.x + roi.width; ++x) {
      const float z = metres(depth.at<T>(y, x));
      if (z > 0.f) points.push_back(pixelPoint(camera, x, y, z));
    }
  return points;
}

}  // namespace

PointCloud backProject(const cv::Mat& depth_m, const Camera& camera, cv::Rect roi) {
  return backProjectAny<float>(depth_m, camera, roi, [](float d) { return d; });
}

PointCloud backProjectMm(const cv::Mat& depth_mm, const Camera& camera, cv::Rect roi) {
  return backProjectAny<uint16_t>(depth_mm, camera, roi, [](uint16_t d) { return 0.001f * d; });
}

PointCloud visibleSurface(const Mesh& mesh, const Camera& camera, const Pose& pose) {
  return backProject(renderReference(mesh, camera, pose).depth, camera);
}

PointCloud syntheticCrop(const Mesh& mesh, const Camera& camera, const Pose& truth, float noise_m,
                         float outlier_share, std::mt19937& rng, float background_m, int margin_px) {
  cv::Mat depth = renderReference(mesh, camera, truth).depth;
  cv::Rect box = cv::boundingRect(depth > 0.f);
  box = cv::Rect(box.x - margin_px, box.y - margin_px, box.width + 2 * margin_px, box.height + 2 * margin_px) &
        cv::Rect(0, 0, depth.cols, depth.rows);
  const float z_background = truth.t.z() + background_m;
  for (int y = box.y; y < box.y + box.height; ++y)
    for (int x = box.x; x < box.x + box.width; ++x)
      if (depth.at<float>(y, x) <= 0.f) depth.at<float>(y, x) = z_background;
  PointCloud points = backProject(depth, camera, box);

  std::normal_distribution<float> noise(0.f, noise_m);
  if (noise_m > 0.f)
    for (auto& p : points) p += Eigen::Vector3f(noise(rng), noise(rng), noise(rng));

  Eigen::AlignedBox3f bounds;
  for (const auto& p : points) bounds.extend(p);
  const auto outliers = static_cast<std::size_t>(outlier_share * float(points.size()) / (1.f - outlier_share));
  std::uniform_real_distribution<float> unit(0.f, 1.f);
  for (std::size_t i = 0; i < outliers; ++i) {
    const Eigen::Vector3f u(unit(rng), unit(rng), unit(rng));
    points.push_back(bounds.min() + u.cwiseProduct(bounds.sizes()));
  }
  std::shuffle(points.begin(), points.end(), rng);
  return points;
}

Pose inverse(const Pose& pose) { return {pose.R.transpose(), -(pose.R.transpose() * pose.t)}; }

Pose perturbed(const Pose& pose, const Eigen::Vector3f& axis, float degrees, const Eigen::Vector3f& shift_m) {
  const Eigen::Matrix3f dR = Eigen::AngleAxisf(degrees * float(M_PI) / 180.f, axis.normalized()).toRotationMatrix();
  return {dR * pose.R, pose.t + shift_m};
}

float rotationErrorDeg(const Eigen::Matrix3f& a, const Eigen::Matrix3f& b) {
  const float c = std::clamp(0.5f * ((a.transpose() * b).trace() - 1.f), -1.f, 1.f);
  return std::acos(c) * 180.f / float(M_PI);
}

float translationError(const Pose& a, const Pose& b) { return (a.t - b.t).norm(); }

float addError(const PointCloud& object_points, const Pose& a, const Pose& b) {
  double sum = 0;
  for (const auto& p : object_points) sum += ((a.R * p + a.t) - (b.R * p + b.t)).norm();
  return object_points.empty() ? 0.f : float(sum / double(object_points.size()));
}

std::vector<Pose> hypothesesAround(const Pose& truth, int n, float degrees, float shift_m, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<float> g(0.f, 1.f);
  std::vector<Pose> poses;
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector3f axis(g(rng), g(rng), g(rng)), shift(g(rng), g(rng), g(rng));
    poses.push_back(perturbed(truth, axis, degrees, shift_m * shift.normalized()));
  }
  return poses;
}

}  // namespace vkpose::test
