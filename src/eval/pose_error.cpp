// ADD and ADI (Hinterstoisser et al., ACCV 2012), with an exact k-d tree for ADI's
// closest-point search.
#include <algorithm>
#include <cmath>
#include <limits>

#include "vkpose/evaluation.hpp"

namespace vkpose {
namespace {
// Ranges this small are scanned instead of split further.
constexpr std::size_t kLeafSize = 8;
}  // namespace

PointIndex::PointIndex(std::vector<Eigen::Vector3f> points) : points_(std::move(points)), axis_(points_.size(), 0) {
  build(0, points_.size());
}

void PointIndex::build(std::size_t lo, std::size_t hi) {
  if (hi - lo <= kLeafSize) return;
  Eigen::Vector3f lo_corner = points_[lo], hi_corner = points_[lo];
  for (std::size_t i = lo + 1; i < hi; ++i) {
    lo_corner = lo_corner.cwiseMin(points_[i]);
    hi_corner = hi_corner.cwiseMax(points_[i]);
  }
  int axis = 0;
  (hi_corner - lo_corner).maxCoeff(&axis);
  const std::size_t mid = lo + (hi - lo) / 2;
  std::nth_element(points_.begin() + static_cast<std::ptrdiff_t>(lo),
                   points_.begin() + static_cast<std::ptrdiff_t>(mid),
                   points_.begin() + static_cast<std::ptrdiff_t>(hi),
                   [axis](const Eigen::Vector3f& a, const Eigen::Vector3f& b) { return a[axis] < b[axis]; });
  axis_[mid] = static_cast<uint8_t>(axis);
  build(lo, mid);
  build(mid + 1, hi);
}

void PointIndex::search(std::size_t lo, std::size_t hi, const Eigen::Vector3f& q, float& best_sq) const {
  if (hi - lo <= kLeafSize) {
    for (std::size_t i = lo; i < hi; ++i) best_sq = std::min(best_sq, (points_[i] - q).squaredNorm());
    return;
  }
  const std::size_t mid = lo + (hi - lo) / 2;
  best_sq = std::min(best_sq, (points_[mid] - q).squaredNorm());
  const float diff = q[axis_[mid]] - points_[mid][axis_[mid]];
  // Points left of mid are <= the split value, points right of it >= it.
  if (diff < 0) {
    search(lo, mid, q, best_sq);
    if (diff * diff < best_sq) search(mid + 1, hi, q, best_sq);
  } else {
    search(mid + 1, hi, q, best_sq);
    if (diff * diff < best_sq) search(lo, mid, q, best_sq);
  }
}

float PointIndex::nearestDistance(const Eigen::Vector3f& q) const {
  float best_sq = std::numeric_limits<float>::infinity();
  search(0, points_.size(), q, best_sq);
  return std::sqrt(best_sq);
}

float addError(const std::vector<Eigen::Vector3f>& points, const Eigen::Matrix3f& R_est, const Eigen::Vector3f& t_est,
               const Eigen::Matrix3f& R_gt, const Eigen::Vector3f& t_gt) {
  if (points.empty()) return 0.f;
  // (R_est p + t_est) - (R_gt p + t_gt) = dR p + dt
  const Eigen::Matrix3f dR = R_est - R_gt;
  const Eigen::Vector3f dt = t_est - t_gt;
  double sum = 0;
  for (const auto& p : points) sum += (dR * p + dt).norm();
  return static_cast<float>(sum / static_cast<double>(points.size()));
}

float adiError(const PointIndex& index, const Eigen::Matrix3f& R_est, const Eigen::Vector3f& t_est,
               const Eigen::Matrix3f& R_gt, const Eigen::Vector3f& t_gt) {
  const auto& points = index.points();
  if (points.empty()) return 0.f;
  // min_q |R_est q + t_est - x| = min_q |q - R_est^T (x - t_est)| for a rotation R_est, so the
  // ground-truth points are brought into the estimate's object frame and searched there.
  const Eigen::Matrix3f A = R_est.transpose() * R_gt;
  const Eigen::Vector3f b = R_est.transpose() * (t_gt - t_est);
  double sum = 0;
  for (const auto& p : points) sum += index.nearestDistance(A * p + b);
  return static_cast<float>(sum / static_cast<double>(points.size()));
}

}  // namespace vkpose
