// Pose refinement with PCL (docs/pipeline.md, stage 7): MLS smoothing, voxel grid, adaptive ICP.
// The only translation unit that includes PCL headers (about 10 s to compile).
#include "pose/refine.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>

#include <Eigen/Geometry>
#include <fmt/core.h>

#include "geometry/nearest_neighbours.hpp"
#include "geometry/point_cloud.hpp"
#include "vkpose/device.hpp"
#include "vkpose/geometry.hpp"

// GCC 12 reports false -Warray-bounds from inside Eigen/PCL templates (docs/measured.md); the
// file's build options silence it for this translation unit only (CMakeLists.txt).
#include <pcl/common/transforms.h>
#include <pcl/filters/voxel_grid.h>
#include <pcl/kdtree/kdtree_flann.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>
#include <pcl/registration/icp.h>
#include <pcl/registration/transformation_estimation_svd.h>
#include <pcl/search/kdtree.h>
#include <pcl/surface/mls.h>

#include "vkpose/error.hpp"

namespace vkpose {
namespace {

using Cloud = pcl::PointCloud<pcl::PointXYZ>;
using Clock = std::chrono::steady_clock;

double msSince(Clock::time_point t0) { return std::chrono::duration<double, std::milli>(Clock::now() - t0).count(); }

Cloud::Ptr toPcl(const PointCloud& points) {
  auto cloud = pcl::make_shared<Cloud>();
  cloud->reserve(points.size());
  for (const auto& p : points)
    if (p.allFinite()) cloud->push_back(pcl::PointXYZ(p.x(), p.y(), p.z()));
  cloud->is_dense = true;
  return cloud;
}

PointCloud fromPcl(const Cloud& cloud) {
  PointCloud points;
  points.reserve(cloud.size());
  for (const auto& p : cloud) points.emplace_back(p.x, p.y, p.z);
  return points;
}

Cloud::Ptr voxelPcl(const Cloud::Ptr& in, float voxel) {
  if (!(voxel > 0.f) || in->empty()) return in;
  pcl::VoxelGrid<pcl::PointXYZ> grid;
  grid.setInputCloud(in);
  grid.setLeafSize(voxel, voxel, voxel);
  auto out = pcl::make_shared<Cloud>();
  grid.filter(*out);
  return out;
}

Cloud::Ptr mlsPcl(const Cloud::Ptr& in, float radius, int order, float seed_voxel) {
  if (in->empty()) return in;
  pcl::MovingLeastSquares<pcl::PointXYZ, pcl::PointXYZ> mls;  // one thread: callers run hypotheses in parallel
  mls.setInputCloud(in);
  if (seed_voxel > 0.f) {  // neighbourhoods still use all points
    auto seeds = pcl::make_shared<pcl::Indices>();
    for (const std::size_t i : voxelSeedIndices(fromPcl(*in), seed_voxel)) seeds->push_back(static_cast<pcl::index_t>(i));
    mls.setIndices(seeds);
  }
  mls.setSearchMethod(pcl::make_shared<pcl::search::KdTree<pcl::PointXYZ>>(false));
  mls.setSearchRadius(radius);
  mls.setPolynomialOrder(order);
  mls.setComputeNormals(false);
  Cloud fitted;
  mls.process(fitted);
  auto out = pcl::make_shared<Cloud>();  // a degenerate neighbourhood can give a NaN point
  out->reserve(fitted.size());
  for (const auto& p : fitted)
    if (std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z)) out->push_back(p);
  return out;
}

}  // namespace

namespace {

/// PCL's transformation-epsilon test on one iteration's increment: squared translation and
/// 1 - cos(rotation angle) both within epsilon.
bool smallStep(const Eigen::Matrix4f& step, double epsilon) {
  const double cos_angle = 0.5 * (double(step(0, 0)) + step(1, 1) + step(2, 2) - 1.0);
  const double translation_sqr = step.block<3, 1>(0, 3).cast<double>().squaredNorm();
  return 1.0 - cos_angle <= epsilon && translation_sqr <= epsilon;
}

/// The paper's adaptive ICP. A fixed correspondence threshold must be chosen before the error
/// of the initial pose is known: too small and the true pairs of a pose that is centimetres
/// off are all rejected (ICP stalls or drifts), too large and clutter next to the object
/// (the table, neighbouring objects) pulls the fit. He, Rojas and Guan instead tie the
/// threshold to the current misalignment: at every iteration it is a fraction of the largest
/// nearest-neighbour distance. The coarse stage (90%) drops only the worst pairs, so it can
/// move a long way from a rough initial pose; the fine stage (45%) then keeps the closest
/// pairs only, which trims clutter and occluded parts and tightens the fit.
class AdaptiveIcp {
 public:
  /// model: object frame; scene: camera frame (the search grid is built once, per call, with
  /// cells of `cell` metres: the voxel filter's leaf size, about one scene point a cell).
  AdaptiveIcp(Cloud::ConstPtr model, Cloud::ConstPtr scene, std::size_t min_pairs, float cell)
      : model_(std::move(model)), scene_(std::move(scene)), min_pairs_(min_pairs), nearest_scene_(fromPcl(*scene_), cell) {}

  /// The model points the next stages pair (object frame).
  void setModel(Cloud::ConstPtr model) {
    model_ = std::move(model);
    nearest_.clear();
  }

  /// Runs one stage from cam_T_model. Returns true when it converged within the limit;
  /// false when it hit the limit or ran out of pairs (cam_T_model keeps the last pose).
  bool stage(float fraction, int max_iterations, double epsilon, Eigen::Matrix4f& cam_T_model, int& iterations) {
    for (int i = 0; i < max_iterations; ++i) {
      pair(cam_T_model, fraction);
      if (pairs_src_.size() < min_pairs_) return false;
      Eigen::Matrix4f step;
      svd_.estimateRigidTransformation(moved_, pairs_src_, *scene_, pairs_tgt_, step);
      if (!step.allFinite()) return false;
      cam_T_model = step * cam_T_model;
      ++iterations;
      if (smallStep(step, epsilon)) return true;
    }
    return false;
  }

  /// Mean squared distance of the pairs at cam_T_model within `fraction` of the largest pair
  /// distance; fills the pair count and threshold used.
  double fitness(const Eigen::Matrix4f& cam_T_model, float fraction, std::size_t& pairs, float& threshold) {
    threshold = pair(cam_T_model, fraction);
    return meanPairDistanceSqr(pairs);
  }

  /// The same with a fixed threshold (metres).
  double fitnessFixed(const Eigen::Matrix4f& cam_T_model, float threshold, std::size_t& pairs) {
    pair(cam_T_model, 0.f, threshold);
    return meanPairDistanceSqr(pairs);
  }

 private:
  /// Moves the model to cam_T_model, finds each point's nearest scene point and keeps the pairs
  /// within fraction * (largest pair distance), or within `fixed` when fraction is 0.
  /// Returns the threshold.
  float pair(const Eigen::Matrix4f& cam_T_model, float fraction, float fixed = 0.f) {
    pcl::transformPointCloud(*model_, moved_, cam_T_model);
    // The last pairing's scene points are hints for the same model points (setModel clears them).
    nearest_.resize(moved_.size(), -1);
    dist_sqr_.resize(moved_.size());
    float max_sqr = 0.f;
    for (std::size_t i = 0; i < moved_.size(); ++i) {
      nearest_[i] = nearest_scene_.nearest(moved_[i].getVector3fMap(), nearest_[i], dist_sqr_[i]);
      max_sqr = std::max(max_sqr, dist_sqr_[i]);
    }
    const float threshold = fraction > 0.f ? fraction * std::sqrt(max_sqr) : fixed;
    const float threshold_sqr = threshold * threshold;
    pairs_src_.clear();
    pairs_tgt_.clear();
    for (std::size_t i = 0; i < moved_.size(); ++i)
      if (dist_sqr_[i] <= threshold_sqr) {
        pairs_src_.push_back(static_cast<pcl::index_t>(i));
        pairs_tgt_.push_back(nearest_[i]);
      }
    return threshold;
  }

  double meanPairDistanceSqr(std::size_t& pairs) const {
    double sum = 0;
    for (auto i : pairs_src_) sum += dist_sqr_[static_cast<std::size_t>(i)];
    pairs = pairs_src_.size();
    return pairs ? sum / double(pairs) : 0.0;
  }

  Cloud::ConstPtr model_, scene_;
  std::size_t min_pairs_;
  NearestNeighbours nearest_scene_;
  pcl::registration::TransformationEstimationSVD<pcl::PointXYZ, pcl::PointXYZ> svd_;
  Cloud moved_;
  pcl::Indices pairs_src_, pairs_tgt_, nearest_;
  std::vector<float> dist_sqr_;
};

/// Plain pcl::IterativeClosestPoint with a fixed threshold, the baseline. Exposes the
/// iteration count, which PCL keeps protected.
class FixedIcp : public pcl::IterativeClosestPoint<pcl::PointXYZ, pcl::PointXYZ> {
 public:
  int iterations() const { return nr_iterations_; }
  /// PCL reports "converged" when the iteration limit is reached; count only real convergence.
  bool reallyConverged() const {
    using State = pcl::registration::DefaultConvergenceCriteria<float>::ConvergenceState;
    const auto state = convergence_criteria_->getConvergenceState();
    return hasConverged() && state != State::CONVERGENCE_CRITERIA_ITERATIONS &&
           state != State::CONVERGENCE_CRITERIA_NOT_CONVERGED &&
           state != State::CONVERGENCE_CRITERIA_NO_CORRESPONDENCES;
  }
};

Eigen::Matrix4f toMatrix(const Pose& pose) {
  Eigen::Matrix4f m = Eigen::Matrix4f::Identity();
  m.topLeftCorner<3, 3>() = pose.R;
  m.topRightCorner<3, 1>() = pose.t;
  return m;
}

Pose toPose(const Eigen::Matrix4f& m) {
  Pose pose;
  // Re-orthonormalize: float products of 60 increments drift slightly off SO(3).
  pose.R = Eigen::Quaternionf(Eigen::Matrix3f(m.topLeftCorner<3, 3>())).normalized().toRotationMatrix();
  pose.t = m.topRightCorner<3, 1>();
  return pose;
}

}  // namespace

std::vector<int> nearestByPclKdTree(const PointCloud& cloud, const PointCloud& queries) {
  // toPcl drops non-finite points: map the tree's indices back to the input's.
  std::vector<int> kept;
  for (std::size_t i = 0; i < cloud.size(); ++i)
    if (cloud[i].allFinite()) kept.push_back(static_cast<int>(i));
  std::vector<int> out(queries.size(), -1);
  if (kept.empty()) return out;
  pcl::KdTreeFLANN<pcl::PointXYZ> tree;
  tree.setInputCloud(toPcl(cloud));
  pcl::Indices index;
  std::vector<float> dist_sqr;
  for (std::size_t q = 0; q < queries.size(); ++q)
    if (queries[q].allFinite() && tree.nearestKSearch(pcl::PointXYZ(queries[q].x(), queries[q].y(), queries[q].z()), 1,
                                                      index, dist_sqr) == 1)
      out[q] = kept[static_cast<std::size_t>(index[0])];
  return out;
}

PointCloud voxelFilter(const PointCloud& cloud, float voxel) {
  if (!std::isfinite(voxel)) throw InputError(fmt::format("voxel size must be finite, got {}", voxel));
  return fromPcl(*voxelPcl(toPcl(cloud), voxel));
}

PointCloud smoothMlsPcl(const PointCloud& scene, float radius, int order, float seed_voxel) {
  validateMls(radius, order, seed_voxel);
  return fromPcl(*mlsPcl(toPcl(scene), radius, order, seed_voxel));
}

RefineResult refinePose(const PointCloud& model_points, const PointCloud& scene_points, const Pose& initial,
                        const RefineParams& params, FinePoints fine_points) {
  validateRefineParams(params);
  RefineResult result;
  result.pose = initial;

  auto t0 = Clock::now();
  Cloud::Ptr scene = toPcl(params.mls ? smoothMls(scene_points, params.mls_radius, params.mls_polynomial_order,
                                                  params.mls_at_voxel_seeds ? params.voxel_size : 0.f,
                                                  params.mls_max_neighbours)
                                      : scene_points);
  result.mls_ms = msSince(t0);

  t0 = Clock::now();
  scene = voxelPcl(scene, params.voxel_size);
  const Cloud::Ptr model = voxelPcl(toPcl(model_points), params.voxel_size);
  result.voxel_ms = msSince(t0);
  result.scene_points = scene->size();
  result.model_points = model->size();

  const std::size_t min_points = std::max<std::size_t>(params.min_points, 3);  // SVD needs 3 pairs
  if (scene->size() < min_points || model->size() < min_points) return result;

  t0 = Clock::now();
  Eigen::Matrix4f cam_T_model = toMatrix(initial);
  // The grid's cell: the voxel filter's leaf (one scene point a cell), 4 mm without a filter.
  AdaptiveIcp icp(model, scene, min_points, params.voxel_size > 0.f ? params.voxel_size : 0.004f);
  if (params.fixed_max_correspondence_m > 0.f) {
    FixedIcp fixed;
    fixed.setInputSource(model);
    fixed.setInputTarget(scene);
    fixed.setMaxCorrespondenceDistance(params.fixed_max_correspondence_m);
    fixed.setMaximumIterations(params.coarse_iterations + params.fine_iterations);
    fixed.setTransformationEpsilon(params.convergence_epsilon);
    Cloud aligned;
    fixed.align(aligned, cam_T_model);
    result.iterations = fixed.iterations();
    result.converged = fixed.reallyConverged();
    if (fixed.hasConverged()) cam_T_model = fixed.getFinalTransformation();
    result.max_correspondence_m = params.fixed_max_correspondence_m;
    result.fitness = icp.fitnessFixed(cam_T_model, result.max_correspondence_m, result.correspondences);
  } else {
    // The coarse stage only has to bring the pose near: a subsample of the model does that
    // at a fraction of the pairing (coarse_max_points). The fine stage runs even when the
    // coarse one hit its limit: it starts closer anyway.
    const auto limit = static_cast<std::size_t>(params.coarse_max_points);
    Cloud::Ptr thinned = model;
    if (limit > 0 && model->size() > limit) {
      const std::size_t k = (model->size() + limit - 1) / limit;
      auto every_kth = pcl::make_shared<Cloud>();
      for (std::size_t i = 0; i < model->size(); i += k) every_kth->push_back((*model)[i]);
      if (every_kth->size() >= min_points) thinned = every_kth;
    }
    icp.setModel(thinned);
    result.coarse_converged = icp.stage(params.coarse_fraction, params.coarse_iterations,
                                        params.convergence_epsilon, cam_T_model, result.iterations);
    if (fine_points == FinePoints::All) icp.setModel(model);
    const bool fine = icp.stage(params.fine_fraction, params.fine_iterations, params.convergence_epsilon,
                                cam_T_model, result.iterations);
    result.converged = params.fine_iterations > 0 ? fine : result.coarse_converged;  // 0: stage skipped
    result.fitness = icp.fitness(cam_T_model, params.fine_fraction, result.correspondences, result.max_correspondence_m);
  }
  result.pose = toPose(cam_T_model);
  result.icp_ms = msSince(t0);
  return result;
}

}  // namespace vkpose
