#pragma once
// Pose verification (DESIGN.md stage 8; He, Rojas, Guan, section on hypothesis verification):
// the collision rate phi is the share of the posed model's visible points that fall into
// occupied cells of an octree built from the scene points. OctoMap stays inside
// src/pose/verify.cpp.
#include <cstddef>

#include "vkpose/point_cloud.hpp"

namespace vkpose {

struct VerifyParams {
  /// Octree leaf size, metres. Real depth is noisy: on LM-O (object 5, about 1 m away) a
  /// correct refined pose scored 0.50 at 4 mm and 0.77 at 8 mm, a pose 2 cm off at most 0.15
  /// and 0.35 (tests/verify_test.cpp). Tune with the threshold.
  float resolution = 0.004f;
  float threshold = 0.5f;  ///< accept if collision rate > threshold (placeholder until measured)
  float crop_margin = 0.02f;  ///< scene points within the model's box grown by this (metres) go in the octree
};

struct VerifyResult {
  float collision_rate = 0;  ///< phi = hits / model_points, 0 when there are no model points
  std::size_t model_points = 0, hits = 0;  ///< finite model points; those in occupied cells
  std::size_t scene_points = 0;            ///< scene points inserted (after the crop)
  bool accepted = false;                   ///< collision_rate > threshold
  double ms = 0;
};

/// Throws InputError naming the bad value.
void validateVerifyParams(const VerifyParams& params);

/// visible_model_points: camera-frame points of the model surface as the camera sees it at the
/// pose under test. scene_points: camera-frame scene points (a crop or the whole frame).
/// Non-finite points are ignored; empty inputs give phi = 0, rejected. Thread-safe.
VerifyResult verifyPose(const PointCloud& visible_model_points, const PointCloud& scene_points,
                        const VerifyParams& params = {});

}  // namespace vkpose
