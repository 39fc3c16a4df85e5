#pragma once
// Pose refinement (DESIGN.md stage 7; He, Rojas, Guan, "A 3D Object Detection and Pose
// Estimation Pipeline Using RGB-D Images", section on pose refinement): moving-least-squares
// smoothing of the scene crop, a voxel grid to bring model and scene to one density, then ICP
// from coarse to fine with a correspondence threshold recomputed at every iteration.
// PCL does the work; it stays inside src/pose/refine.cpp.
#include <cstddef>

#include "vkpose/point_cloud.hpp"
#include "vkpose/render.hpp"  // Pose

namespace vkpose {

struct RefineParams {
  /// Moving least squares smoothing of the scene crop before registration.
  bool mls = true;
  /// MLS neighbourhood radius, metres. At 0.7 m a Kinect-class sensor samples about every
  /// 1.2 mm, so 1 cm holds ~200 points: enough to average its 1-3 mm depth noise down with a
  /// quadric fit, yet small against the 10-20 cm LM-O objects, so edges and curvature survive.
  float mls_radius = 0.01f;
  int mls_polynomial_order = 2;  ///< 2: quadric fit (follows curved surfaces); 1: plane
  /// true: fit MLS only at one seed point per voxel_size voxel (the neighbourhoods still hold
  /// every point), since the voxel grid keeps one point per voxel anyway: the same smoothing
  /// for about a third of the work (LM-O crop of 8.8k points: 23 vs 68 ms). false: fit at
  /// every point, then voxel-filter (the paper's literal order).
  bool mls_at_voxel_seeds = true;
  /// Both clouds are voxel-filtered to this leaf size (metres), so that each surface patch
  /// weighs the same in the fit whatever the sensor's or the model's sampling. 0: no filter.
  float voxel_size = 0.004f;
  /// Coarse stage: max correspondence distance = this fraction of the largest distance among
  /// the current nearest-neighbour pairs, recomputed each iteration (the paper: 90%).
  float coarse_fraction = 0.9f;
  float fine_fraction = 0.45f;  ///< fine stage, the same with 45% (the paper)
  int coarse_iterations = 30;   ///< iteration limit of the coarse stage (0: skip it)
  int fine_iterations = 30;     ///< iteration limit of the fine stage (0: skip it)
  /// A stage has converged when one iteration moves the pose by less than this: squared
  /// translation (m^2) and 1 - cos(rotation angle), PCL's transformation epsilon criterion.
  double convergence_epsilon = 1e-6;
  /// Fewer points than this in either filtered cloud, or fewer pairs within the threshold:
  /// no registration (converged = false).
  std::size_t min_points = 10;
  /// Baseline for comparison: > 0 replaces the two adaptive stages by one plain
  /// pcl::IterativeClosestPoint run with this fixed max correspondence distance (metres) and
  /// coarse_iterations + fine_iterations iterations. Filtering is unchanged.
  float fixed_max_correspondence_m = 0.f;
};

struct RefineResult {
  /// Refined object-to-camera pose; the initial one when the clouds are too small. When ICP
  /// hits its limits or runs out of pairs, the pose it reached.
  Pose pose;
  /// Mean squared distance (m^2) of the final correspondences: model points at the refined pose
  /// paired with their nearest scene point, pairs within max_correspondence_m only.
  double fitness = 0;
  std::size_t correspondences = 0;  ///< pairs that fitness averages
  float max_correspondence_m = 0;   ///< the last threshold used (adaptive or fixed)
  int iterations = 0;               ///< coarse + fine
  bool converged = false;           ///< the last stage run (fine, coarse or fixed) converged within its limit
  bool coarse_converged = false;    ///< the coarse stage converged within its limit
  std::size_t scene_points = 0, model_points = 0;  ///< after filtering
  double mls_ms = 0, voxel_ms = 0, icp_ms = 0;     ///< time per step
};

/// Throws InputError naming the bad value.
void validateRefineParams(const RefineParams& params);

/// Refines `initial` so that `model_points` (object frame, metres) fall onto `scene_points`
/// (camera-frame crop, metres). Pass the model's surface as seen from about the initial pose
/// (rendered there and moved to the object frame), as stage 6 has it: with all mesh vertices,
/// the back of the model sets the largest pair distance, the adaptive threshold stays wide and
/// the back pulls the fit towards the camera (measured: 5-10 mm off). Non-finite points
/// are ignored. Too few points after filtering (< params.min_points) or no usable pairs give
/// converged = false with the initial pose; never throws on such input. Throws InputError on
/// nonsense parameters (negative sizes, fractions outside (0, 1]). Thread-safe: all state is
/// local to the call.
RefineResult refinePose(const PointCloud& model_points, const PointCloud& scene_points, const Pose& initial,
                        const RefineParams& params = {});

/// Moving least squares: each point projected onto a polynomial of `order` fitted to its
/// neighbours within `radius` (metres). Points with fewer than 3 neighbours are dropped.
/// seed_voxel > 0: only the first point of each voxel of that size is fitted and returned
/// (its neighbourhood still uses every point).
PointCloud smoothMls(const PointCloud& scene, float radius, int order, float seed_voxel = 0.f);

/// Voxel grid: one point per occupied cube of side `voxel` (metres), the centroid of its
/// points. voxel <= 0 returns the finite points unchanged.
PointCloud voxelFilter(const PointCloud& cloud, float voxel);

}  // namespace vkpose
