#pragma once
// Checks the dataset readers share.
#include <cmath>
#include <optional>
#include <string>

#include <Eigen/Core>
#include <Eigen/LU>
#include <fmt/format.h>

namespace vkpose::eval {

/// Largest |(R^T R - I)_ij| a rotation read from a file may have. Real annotations are not
/// exact: LM-O's ground truth of the drill in scene 2 image 3 is off by 2e-3, Tejani et al.'s
/// poses by 2.4e-6. Matrices further off than 1% are not rotations.
inline constexpr double kRotationTolerance = 1e-2;

/// Why R is not a rotation (not orthonormal within kRotationTolerance, a reflection, or not
/// finite), or nothing when it is one.
inline std::optional<std::string> rotationProblem(const Eigen::Matrix3d& R) {
  if (!R.allFinite()) return std::string("R is not finite");
  const double off = (R.transpose() * R - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff();
  const double det = R.determinant();
  if (off > kRotationTolerance || det < 0)
    return fmt::format("R is not a rotation (max |R^T R - I| = {:.3g}, det R = {:.3g})", off, det);
  return std::nullopt;
}

}  // namespace vkpose::eval
