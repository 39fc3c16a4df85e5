#pragma once
// Pose verification (DESIGN.md stage 8; He, Rojas, Guan, section on hypothesis verification):
// the collision rate phi is the share of the posed model's visible points that fall into
// occupied cells of an octree built from the scene points. OctoMap stays inside
// src/pose/verify.cpp.
#include <cstddef>

#include <opencv2/core.hpp>

#include "vkpose/camera.hpp"
#include "vkpose/point_cloud.hpp"

namespace vkpose {

struct VerifyParams {
  /// Octree leaf size, metres. Real depth is noisy: on LM-O (object 5, about 1 m away) a
  /// correct refined pose scored 0.50 at 4 mm and 0.77 at 8 mm, a pose 2 cm off at most 0.15
  /// and 0.35 (tests/verify_test.cpp). Tune with the threshold.
  float resolution = 0.004f;
  /// Accept if the collision rate exceeds this. Measured on LM-O (scene 2, image 3) at 4 mm
  /// leaves: correct refined poses 0.42-0.64, wrong ones that pass the other two tests up to 0.38.
  float threshold = 0.4f;
  float crop_margin = 0.02f;  ///< scene points within the model's box grown by this (metres) go in the octree
  /// Free-space test: a visible model point whose pixel sees the scene this much (metres)
  /// farther away cannot be there (the camera looks through it). The collision rate alone
  /// accepts a flat face of a model laid on any flat surface; the points that stick out of it
  /// then float in front of that surface.
  float see_through_tolerance = 0.015f;
  /// Accept only if at most this share of the visible model points (with scene depth) is
  /// seen through.
  float max_see_through = 0.15f;
  /// Silhouette test: an object that stands where it is claimed shows a depth step along most
  /// of its outline (the background lies farther). A model sunk into a table or a wall, with
  /// one flat face flush with it, fits the depth everywhere and has a collision rate as high
  /// as a true object's (measured on LM-O: a hole puncher laid into the paper markers, phi
  /// 0.59), but shows no step. A step is a jump of at least `silhouette_jump` metres.
  float silhouette_jump = 0.01f;
  /// Accept only if at least this share of the outline's samples (where the scene has depth
  /// on both sides, and nothing nearer outside) steps back.
  float min_silhouette_support = 0.55f;
};

struct VerifyResult {
  float collision_rate = 0;  ///< phi = hits / model_points, 0 when there are no model points
  std::size_t model_points = 0, hits = 0;  ///< finite model points; those in occupied cells
  std::size_t scene_points = 0;            ///< scene points inserted (after the crop)
  bool accepted = false;                   ///< collision_rate > threshold
  double ms = 0;
};

/// How the scene depth at the pixels of camera-frame model points compares with theirs, as
/// shares of the points whose pixel has scene depth (all 0 when none has).
struct DepthAgreement {
  float fits = 0.f;          ///< within the tolerance
  float seen_through = 0.f;  ///< the scene lies farther: the camera sees through the model
  float occluded = 0.f;      ///< the scene lies nearer: something in front, or the model is sunk into a surface
  std::size_t with_depth = 0;
};
/// scene_depth_m: CV_32FC1 metres, 0 = none.
DepthAgreement depthAgreement(const PointCloud& model_points, const cv::Mat& scene_depth_m, const Camera& camera,
                              float tolerance);

/// The silhouette test's share (see VerifyParams::silhouette_jump): the outline of the
/// camera-frame model points projected into the image, sampled every pixel; at each sample the
/// scene depth 3 px inside and 4 px outside along the outline's normal. Samples where either
/// has no depth or the outside is nearer (an occluder) are left out; the share is of the rest
/// whose outside lies at least `jump` farther. 0 when no sample is usable.
float silhouetteSupport(const PointCloud& model_points, const cv::Mat& scene_depth_m, const Camera& camera, float jump);

/// Throws InputError naming the bad value.
void validateVerifyParams(const VerifyParams& params);

/// visible_model_points: camera-frame points of the model surface as the camera sees it at the
/// pose under test. scene_points: camera-frame scene points (a crop or the whole frame).
/// Non-finite points are ignored; empty inputs give phi = 0, rejected. Thread-safe.
VerifyResult verifyPose(const PointCloud& visible_model_points, const PointCloud& scene_points,
                        const VerifyParams& params = {});

}  // namespace vkpose
