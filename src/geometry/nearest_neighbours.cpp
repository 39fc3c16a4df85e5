#include "geometry/nearest_neighbours.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include <fmt/format.h>

#include "vkpose/error.hpp"

namespace vkpose {

NearestNeighbours::Grid::Grid(const PointCloud& points, float cell_size, std::size_t max_cells) {
  Eigen::Vector3f lo = Eigen::Vector3f::Constant(std::numeric_limits<float>::max()), hi = -lo;
  for (const auto& p : points) lo = lo.cwiseMin(p), hi = hi.cwiseMax(p);
  // Cells grow until the grid fits max_cells (a crop is centimetres wide, so only absurd input
  // gets there). One spare layer: a point on the box's far face needs no clamping, so every
  // point sits in the cell its coordinates say (the search's bound relies on it).
  const Eigen::Vector3f extent = hi - lo;
  for (;;) {
    const Eigen::Vector3f n = (extent / cell_size).array().floor() + 2.f;
    if (n.maxCoeff() <= float(1 << 20) && double(n.x()) * n.y() * n.z() <= double(max_cells)) {
      nx = static_cast<int>(n.x()), ny = static_cast<int>(n.y()), nz = static_cast<int>(n.z());
      break;
    }
    cell_size *= 2.f;
  }
  cell = cell_size;
  inv_cell = 1.f / cell_size;
  origin = lo;
  const std::size_t cells = std::size_t(nx) * std::size_t(ny) * std::size_t(nz);
  std::vector<std::size_t> cell_of(points.size());
  start.assign(cells + 1, 0);
  for (std::size_t i = 0; i < points.size(); ++i) {
    const Eigen::Vector3f c = ((points[i] - origin) * inv_cell).array().floor();
    cell_of[i] = (std::size_t(c.z()) * std::size_t(ny) + std::size_t(c.y())) * std::size_t(nx) + std::size_t(c.x());
    ++start[cell_of[i] + 1];
  }
  for (std::size_t c = 0; c < cells; ++c) start[c + 1] += start[c];
  std::vector<std::uint32_t> fill(start.begin(), start.end() - 1);
  order.resize(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) order[fill[cell_of[i]]++] = static_cast<int>(i);
}

bool NearestNeighbours::Grid::search(const PointCloud& sorted, const Eigen::Vector3f& q, int& best,
                                     float& best_sqr) const {
  // q's cell, possibly outside the grid (clamped far enough out not to overflow).
  const Eigen::Vector3f f = ((q - origin) * inv_cell).array().floor().cwiseMax(-4096.f).cwiseMin(float(1 << 21));
  const int cx = static_cast<int>(f.x()), cy = static_cast<int>(f.y()), cz = static_cast<int>(f.z());
  for (int k = 0; k <= kMaxRing; ++k) {
    // The shell of cells at Chebyshev distance k from q's cell, within the grid.
    for (int z = std::max(cz - k, 0); z <= std::min(cz + k, nz - 1); ++z)
      for (int y = std::max(cy - k, 0); y <= std::min(cy + k, ny - 1); ++y) {
        const bool inner_zy = std::abs(z - cz) < k && std::abs(y - cy) < k;
        const std::size_t row = (std::size_t(z) * std::size_t(ny) + std::size_t(y)) * std::size_t(nx);
        for (int x = std::max(cx - k, 0); x <= std::min(cx + k, nx - 1); ++x) {
          if (inner_zy && std::abs(x - cx) < k) {  // inside the shell: on to its far face
            x = cx + k - 1;
            continue;
          }
          for (std::uint32_t i = start[row + std::size_t(x)], end = start[row + std::size_t(x) + 1]; i < end; ++i) {
            const float d = (sorted[i] - q).squaredNorm();
            if (d < best_sqr) best_sqr = d, best = static_cast<int>(i);
          }
        }
      }
    // Every point not yet seen lies in a cell k + 1 or more away: farther than k cells from q.
    const float reach = static_cast<float>(k) * cell;
    if (best >= 0 && best_sqr <= reach * reach) return true;
  }
  return false;
}

template <class Visit>
void NearestNeighbours::Grid::forCellsOfBall(const Eigen::Vector3f& q, float radius, Visit&& visit) const {
  const Eigen::Vector3f lo = ((q.array() - radius - origin.array()) * inv_cell).floor().matrix();
  const Eigen::Vector3f hi = ((q.array() + radius - origin.array()) * inv_cell).floor().matrix();
  // The overlapped cells, clamped to the grid before the casts (q may be anywhere).
  auto range = [](float a, float b, int n, int& i0, int& i1) {
    i0 = static_cast<int>(std::clamp(a, 0.f, float(n)));
    i1 = static_cast<int>(std::clamp(b, -1.f, float(n - 1)));
    return i0 <= i1;
  };
  int x0, x1, y0, y1, z0, z1;
  if (!range(lo.x(), hi.x(), nx, x0, x1) || !range(lo.y(), hi.y(), ny, y0, y1) || !range(lo.z(), hi.z(), nz, z0, z1))
    return;
  for (int z = z0; z <= z1; ++z)
    for (int y = y0; y <= y1; ++y) {
      const std::size_t row = (std::size_t(z) * std::size_t(ny) + std::size_t(y)) * std::size_t(nx);
      for (std::uint32_t i = start[row + std::size_t(x0)], end = start[row + std::size_t(x1) + 1]; i < end; ++i) visit(i);
    }
}

void NearestNeighbours::Grid::scanBall(const PointCloud& sorted, const Eigen::Vector3f& q, int& best,
                                       float& best_sqr) const {
  forCellsOfBall(q, std::sqrt(best_sqr), [&](std::uint32_t i) {
    const float d = (sorted[i] - q).squaredNorm();
    if (d < best_sqr) best_sqr = d, best = static_cast<int>(i);
  });
}

NearestNeighbours::NearestNeighbours(const PointCloud& points, float cell, std::size_t max_cells) {
  if (!(cell > 0.f) || !std::isfinite(cell))
    throw InputError(fmt::format("nearest-neighbour grid: the cell size must be positive and finite, got {}", cell));
  PointCloud finite;
  std::vector<int> index;
  finite.reserve(points.size());
  for (std::size_t i = 0; i < points.size(); ++i)
    if (points[i].allFinite()) finite.push_back(points[i]), index.push_back(static_cast<int>(i));
  sorted_.assign(points.size(), -1);
  if (finite.empty()) return;
  fine_ = Grid(finite, cell, max_cells);
  points_.reserve(finite.size());
  for (const int i : fine_.order) {
    sorted_[static_cast<std::size_t>(index[static_cast<std::size_t>(i)])] = static_cast<int>(points_.size());
    points_.push_back(finite[static_cast<std::size_t>(i)]);
    original_.push_back(index[static_cast<std::size_t>(i)]);
  }
  coarse_ = Grid(points_, cell * kCoarse, max_cells);
  coarse_sorted_.reserve(points_.size());
  coarse_rank_.resize(points_.size());
  for (std::size_t k = 0; k < coarse_.order.size(); ++k) {
    coarse_sorted_.push_back(points_[static_cast<std::size_t>(coarse_.order[k])]);
    coarse_rank_[static_cast<std::size_t>(coarse_.order[k])] = static_cast<int>(k);
  }
}

int NearestNeighbours::search(const Eigen::Vector3f& q, float bound_sqr, float& dist_sqr) const {
  dist_sqr = std::numeric_limits<float>::infinity();
  if (points_.empty() || !q.allFinite()) return -1;
  int best = -1;
  float best_sqr = std::numeric_limits<float>::infinity();
  // A grid that failed to prove its best still proves that no unseen point lies within its
  // reach: where the bound lies within that, the best seen is the answer (or there is none).
  auto settled = [&](const Grid& g) {
    const float reach = static_cast<float>(kMaxRing) * g.cell;
    return bound_sqr <= reach * reach;
  };
  if (!fine_.search(points_, q, best, best_sqr) && !settled(fine_)) {
    // The fine grid's best is a candidate for the coarse one, as an index into its order.
    int coarse_best = -1;
    if (best >= 0) coarse_best = coarse_rank_[static_cast<std::size_t>(best)];
    const bool proved = coarse_.search(coarse_sorted_, q, coarse_best, best_sqr);
    if (proved || settled(coarse_)) {
      best = coarse_best < 0 ? -1 : coarse_.order[static_cast<std::size_t>(coarse_best)];
    } else {
      ++full_scans_;
      best = -1;
      best_sqr = std::numeric_limits<float>::infinity();
      for (std::size_t i = 0; i < points_.size(); ++i) {
        const float d = (points_[i] - q).squaredNorm();
        if (d < best_sqr) best_sqr = d, best = static_cast<int>(i);
      }
    }
  }
  if (best < 0 || best_sqr > bound_sqr) return -1;
  dist_sqr = best_sqr;
  return best;
}

int NearestNeighbours::nearest(const Eigen::Vector3f& q, float& dist_sqr) const {
  const int best = search(q, std::numeric_limits<float>::infinity(), dist_sqr);
  return best < 0 ? -1 : original_[static_cast<std::size_t>(best)];
}

int NearestNeighbours::nearestWithin(const Eigen::Vector3f& q, float max_dist, float& dist_sqr) const {
  dist_sqr = std::numeric_limits<float>::infinity();
  if (!(max_dist >= 0.f)) return -1;
  const int best = search(q, max_dist * max_dist, dist_sqr);
  return best < 0 ? -1 : original_[static_cast<std::size_t>(best)];
}

int NearestNeighbours::nearest(const Eigen::Vector3f& q, int hint, float& dist_sqr) const {
  const int h = hint >= 0 && static_cast<std::size_t>(hint) < sorted_.size() ? sorted_[static_cast<std::size_t>(hint)] : -1;
  if (h < 0 || !q.allFinite()) return nearest(q, dist_sqr);
  // Every point nearer than the hint lies in the ball through it: scan the cells the ball
  // overlaps, on the fine grid while it spans a few cells, else on the coarse one.
  float best_sqr = (points_[static_cast<std::size_t>(h)] - q).squaredNorm();
  const float reach = static_cast<float>(kMaxRing) * fine_.cell;
  if (best_sqr <= reach * reach) {
    int best = h;
    fine_.scanBall(points_, q, best, best_sqr);
    dist_sqr = best_sqr;
    return original_[static_cast<std::size_t>(best)];
  }
  // Farther (a model point where the scene is occluded or the pose is wrong, centimetres
  // off): the coarse grid's cells within the ball, unless the ball spans so many that one
  // pass over the points costs less.
  const float across = 2.f * std::sqrt(best_sqr) * coarse_.inv_cell + 2.f;
  if (across * across * across <= 0.25f * static_cast<float>(points_.size())) {
    int best = coarse_rank_[static_cast<std::size_t>(h)];
    coarse_.scanBall(coarse_sorted_, q, best, best_sqr);
    dist_sqr = best_sqr;
    return original_[static_cast<std::size_t>(coarse_.order[static_cast<std::size_t>(best)])];
  }
  ++full_scans_;
  int best = h;
  for (std::size_t i = 0; i < points_.size(); ++i) {
    const float d = (points_[i] - q).squaredNorm();
    if (d < best_sqr) best_sqr = d, best = static_cast<int>(i);
  }
  dist_sqr = best_sqr;
  return original_[static_cast<std::size_t>(best)];
}

void NearestNeighbours::within(const Eigen::Vector3f& q, float radius, std::vector<int>& out) const {
  if (points_.empty() || !q.allFinite() || !(radius >= 0.f)) return;
  const float r2 = radius * radius;
  fine_.forCellsOfBall(q, radius, [&](std::uint32_t i) {
    if ((points_[i] - q).squaredNorm() <= r2) out.push_back(original_[i]);
  });
}

}  // namespace vkpose
