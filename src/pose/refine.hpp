#pragma once
// Pose refinement (docs/pipeline.md, stage 7; He, Rojas, Guan, "A 3D Object Detection and Pose
// Estimation Pipeline Using RGB-D Images", section on pose refinement): moving-least-squares
// smoothing of the scene crop, a voxel grid to bring model and scene to one density, then ICP
// from coarse to fine with a correspondence threshold recomputed at every iteration.
// PCL does the work; it stays inside src/pose/refine.cpp.
#include <cstddef>
#include <vector>

#include "geometry/point_cloud.hpp"
#include "vkpose/config.hpp"
#include "vkpose/geometry.hpp"

namespace vkpose {

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

/// The model points ICP's fine stage pairs: all of them (the refinement), or the coarse stage's
/// thinned ones (RefineParams::coarse_max_points; the first fit: a fifth of the pairing, and
/// near enough to where the full fit ends to judge a start by).
enum class FinePoints { All, Thinned };

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
                        const RefineParams& params = {}, FinePoints fine_points = FinePoints::All);

/// Moving least squares: each point projected onto a polynomial of `order` fitted to its
/// neighbours within `radius` (metres), weighted by exp(-d^2 / radius^2) (PCL's
/// MovingLeastSquares with SIMPLE projection; src/pose/mls.cpp). Points with fewer than 3
/// neighbours are dropped, as are non-finite points. seed_voxel > 0: only the first point of
/// each voxel of that size is fitted and returned (its neighbourhood still uses every point).
/// max_neighbours > 0: a larger neighbourhood is thinned to every k-th point, k the smallest
/// that leaves at most max_neighbours (the fit's cost follows the points it sums).
PointCloud smoothMls(const PointCloud& scene, float radius, int order, float seed_voxel = 0.f, int max_neighbours = 0);

/// The same with pcl::MovingLeastSquares and its k-d tree: the peer smoothMls is tested against.
PointCloud smoothMlsPcl(const PointCloud& scene, float radius, int order, float seed_voxel = 0.f);

/// Indices of the first point of each occupied voxel of size `voxel`, in input order (MLS's seeds).
std::vector<std::size_t> voxelSeedIndices(const PointCloud& cloud, float voxel);

/// InputError unless the MLS radius is positive and finite, the polynomial order >= 0 and the
/// seed voxel >= 0 and finite: smoothMls and smoothMlsPcl check the lengths they are given
/// (scaled per object), which the config table's ranges never saw.
void validateMls(float radius, int order, float seed_voxel);

/// For each query, the index of its nearest point of `cloud` by PCL's k-d tree (KdTreeFLANN),
/// -1 for a non-finite query: the peer that NearestNeighbours, ICP's search, is tested against.
std::vector<int> nearestByPclKdTree(const PointCloud& cloud, const PointCloud& queries);

/// Voxel grid: one point per occupied cube of side `voxel` (metres), the centroid of its
/// points. voxel <= 0 returns the finite points unchanged.
PointCloud voxelFilter(const PointCloud& cloud, float voxel);

}  // namespace vkpose
