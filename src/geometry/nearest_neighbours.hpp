#pragma once
// Exact nearest-neighbour search for ICP (docs/pipeline.md, stage 7). ICP asks for the nearest
// scene point of every model point at every iteration; with a k-d tree (PCL's KdTreeFLANN)
// that was 2-4 us a query, 80 % of the refinement. The scene crop is voxel-filtered, so a
// regular grid of the voxel's size holds about one point per occupied cell and almost every
// query is answered exactly from the 27 cells around it.
#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "geometry/point_cloud.hpp"

namespace vkpose {

class NearestNeighbours {
 public:
  /// `cell`: the fine grid's cell size (metres); the voxel filter's leaf size suits. Grids span
  /// the points' bounding box; when one would exceed `max_cells`, its cells grow (the search
  /// stays exact, only slower). Non-finite points are never returned.
  NearestNeighbours(const PointCloud& points, float cell, std::size_t max_cells = std::size_t(1) << 22);

  /// Index of the point nearest to q, and its squared distance; -1 when there are no points.
  /// Exact: the same point a brute-force search finds (ties apart). Searches the fine grid ring
  /// by ring up to kMaxRing, then a grid of kCoarse times larger cells the same way (model
  /// points where the scene is occluded stay centimetres from it at every iteration), then
  /// every point.
  int nearest(const Eigen::Vector3f& q, float& dist_sqr) const;

  /// nearest(), told a point of the cloud (its input index) that the query was near before.
  /// ICP asks again for the same model points after each small move: the distance to the last
  /// answer bounds the new one, so only the cells within it are scanned (about 8 where the
  /// grid search visits 27 to 125). The same distance as nearest(), and the same point but
  /// for ties. A hint of -1 (or a non-finite point) is no hint.
  int nearest(const Eigen::Vector3f& q, int hint, float& dist_sqr) const;

  /// nearest(), for a caller that needs no point farther than `max_dist` (a distance it caps
  /// there): -1 and infinity when none lies within it. The grids' rings decide that, so a
  /// query far from every point costs no whole-cloud scan when max_dist is at most kMaxRing
  /// coarse cells.
  int nearestWithin(const Eigen::Vector3f& q, float max_dist, float& dist_sqr) const;

  /// Indices of the points within `radius` of q (squared distance <= radius^2), appended to
  /// `out` in no particular order. Scans the fine grid's cells that the ball overlaps, so a
  /// cell about the radius's size suits (MLS's neighbourhoods).
  void within(const Eigen::Vector3f& q, float radius, std::vector<int>& out) const;

  std::size_t size() const { return points_.size(); }
  /// Queries answered by the whole-cloud scan since construction (for tests and profiles).
  std::size_t fullScans() const { return full_scans_; }

  static constexpr int kMaxRing = 2;
  static constexpr float kCoarse = 4.f;

 private:
  /// One grid over the points, sorted by cell (CSR).
  struct Grid {
    Grid() = default;
    Grid(const PointCloud& points, float cell, std::size_t max_cells);
    /// Rings 0..kMaxRing around q; updates best / best_sqr (indices into `order`) and returns
    /// true when no point outside the rings can be nearer.
    bool search(const PointCloud& sorted, const Eigen::Vector3f& q, int& best, float& best_sqr) const;
    /// Scans the cells that the ball of radius sqrt(best_sqr) around q overlaps; updates best /
    /// best_sqr (indices into `order`, best may be -1) with any point strictly nearer.
    void scanBall(const PointCloud& sorted, const Eigen::Vector3f& q, int& best, float& best_sqr) const;
    /// Calls visit(i) for every point (its index into the grid's order) of the cells that the
    /// ball of `radius` around q overlaps, row of cells by row.
    template <class Visit>
    void forCellsOfBall(const Eigen::Vector3f& q, float radius, Visit&& visit) const;
    std::vector<int> order;             // sorted[i] = points[order[i]]
    std::vector<std::uint32_t> start;   // a cell's points are sorted[start[c], start[c + 1])
    Eigen::Vector3f origin = Eigen::Vector3f::Zero();
    float cell = 1.f, inv_cell = 1.f;
    int nx = 0, ny = 0, nz = 0;
  };

  /// The nearest point (an index into points_) if it lies within sqrt(bound_sqr), else -1.
  int search(const Eigen::Vector3f& q, float bound_sqr, float& dist_sqr) const;

  PointCloud points_;  // the finite points, in the fine grid's order
  std::vector<int> original_;  // points_[i] was points[original_[i]]
  std::vector<int> sorted_;    // points[i] is points_[sorted_[i]]; -1 for a non-finite point
  Grid fine_, coarse_;         // coarse_ indexes points_ (not the input)
  PointCloud coarse_sorted_;   // points_ in the coarse grid's order
  std::vector<int> coarse_rank_;  // points_[i] is coarse_sorted_[coarse_rank_[i]]
  mutable std::size_t full_scans_ = 0;
};

}  // namespace vkpose
