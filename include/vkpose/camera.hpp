#pragma once
// Pinhole camera intrinsics, read from BOP-style camera files.
#include <string>

#include <Eigen/Core>

namespace vkpose {

struct Camera {
  double fx = 572.4114, fy = 573.57043;  ///< focal lengths, pixels (default: the LINEMOD Kinect)
  double cx = 325.2611, cy = 242.04899;  ///< principal point, pixels
  int width = 640, height = 480;         ///< image size, pixels
  double depth_scale = 1.0;              ///< millimetres per depth-PNG unit (BOP)

  Eigen::Vector2f project(const Eigen::Vector3f& p) const {
    return {static_cast<float>(fx * p.x() / p.z() + cx), static_cast<float>(fy * p.y() / p.z() + cy)};
  }
};

/// Throws InputError when a focal length is not positive and finite, the principal point is
/// not finite, the size is not 1..16384, or the depth scale is not positive.
void validateCamera(const Camera& camera, const std::string& source = "camera");

/// Reads a BOP camera.json ({"fx", "fy", "cx", "cy", "width", "height", "depth_scale"} or
/// {"cam_K": [9 numbers], ...}) or one entry of a scene_camera.json (`entry`: its key; empty:
/// the first entry). Throws InputError naming the file and the missing or bad field.
Camera loadCamera(const std::string& path, const std::string& entry = "");

}  // namespace vkpose
