#pragma once
// Point clouds for the pose tests (refine, verify): rendered visible surfaces, synthetic scene
// crops with noise, a background and outliers, and pose arithmetic and errors.
#include <random>

#include <opencv2/core.hpp>

#include "vkpose/geometry.hpp"
#include "geometry/point_cloud.hpp"
#include "render/render.hpp"

namespace vkpose::test {

/// Camera-frame points (metres) of the pixels of `depth_m` (CV_32F metres, 0: none) inside
/// `roi` (empty: the whole image).
PointCloud backProject(const cv::Mat& depth_m, const Camera& camera, cv::Rect roi = {});
/// The same for a 16-bit depth image in millimetres (a real frame).
PointCloud backProjectMm(const cv::Mat& depth_mm, const Camera& camera, cv::Rect roi = {});

/// The model's surface as the camera sees it at `pose` (camera frame), from renderReference.
PointCloud visibleSurface(const Mesh& mesh, const Camera& camera, const Pose& pose);

/// A scene crop like a detector's: the object rendered at `truth`, a flat background
/// `background_m` behind the object's centre filling the rest of its image box (grown by
/// `margin_px`), Gaussian noise of `noise_m` on each coordinate, and uniform outliers in the
/// crop's 3D box, `outlier_share` of the points.
PointCloud syntheticCrop(const Mesh& mesh, const Camera& camera, const Pose& truth, float noise_m,
                         float outlier_share, std::mt19937& rng, float background_m = 0.05f, int margin_px = 15);

Pose inverse(const Pose& pose);
/// `pose` rotated by `degrees` about `axis` (camera frame, through the object's origin), then
/// shifted by `shift_m`.
Pose perturbed(const Pose& pose, const Eigen::Vector3f& axis, float degrees, const Eigen::Vector3f& shift_m);
float rotationErrorDeg(const Eigen::Matrix3f& a, const Eigen::Matrix3f& b);
float translationError(const Pose& a, const Pose& b);  ///< metres
/// ADD: mean distance between the points placed by the two poses (metres).
float addError(const PointCloud& object_points, const Pose& a, const Pose& b);
/// `n` poses around `truth`, each rotated by `degrees` about a random axis and shifted by
/// `shift_m` in a random direction.
std::vector<Pose> hypothesesAround(const Pose& truth, int n, float degrees, float shift_m, unsigned seed);

}  // namespace vkpose::test
