// Near-symmetries from the mesh (include/vkpose/bank.hpp, near-symmetries): the surface, sampled evenly by
// area, is turned about candidate axes and compared with a second, independent sampling of
// itself. Two samplings of the same surface are a spacing apart even without a turn, so that
// spacing (measured with no turn) is taken off.
#include "vkpose/bank.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <initializer_list>
#include <random>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <fmt/format.h>

#include "geometry/nearest_neighbours.hpp"

namespace vkpose {

namespace {

constexpr int kSamples = 12000;
/// The share of the turned surface that must lie within the tolerance: the rest may stick
/// out (a spout, a seam, a small handle: what only appearance or a close look tells apart).
constexpr float kQuantile = 0.9f;
constexpr std::array<float, 7> kAngles{60.f, 90.f, 120.f, 180.f, 240.f, 270.f, 300.f};

/// Points spread over the surface by area (a fixed seed: training is deterministic).
PointCloud sampleSurface(const Mesh& mesh, int count, unsigned seed) {
  std::vector<double> cumulative;
  cumulative.reserve(mesh.faces.size());
  double total = 0;
  for (const auto& f : mesh.faces) {
    total += 0.5 * (mesh.vertices[f[1]] - mesh.vertices[f[0]]).cross(mesh.vertices[f[2]] - mesh.vertices[f[0]]).norm();
    cumulative.push_back(total);
  }
  PointCloud out;
  if (total <= 0) return out;
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> area(0.0, total);
  std::uniform_real_distribution<float> unit(0.f, 1.f);
  out.reserve(static_cast<std::size_t>(count));
  for (int i = 0; i < count; ++i) {
    const auto k = static_cast<std::size_t>(std::lower_bound(cumulative.begin(), cumulative.end(), area(rng)) -
                                            cumulative.begin());
    const auto& f = mesh.faces[std::min(k, mesh.faces.size() - 1)];
    float u = unit(rng), v = unit(rng);
    if (u + v > 1.f) u = 1.f - u, v = 1.f - v;
    out.push_back(mesh.vertices[f[0]] + u * (mesh.vertices[f[1]] - mesh.vertices[f[0]]) +
                  v * (mesh.vertices[f[2]] - mesh.vertices[f[0]]));
  }
  return out;
}

/// The samples' distances to the surface, capped: a search within `cap` of each point (a turn
/// whose points lie farther is no symmetry whatever the exact figure).
class CappedDistance {
 public:
  /// The index's coarse grid settles every query within the cap (its reach is kMaxRing coarse
  /// cells), so a turned point far from the surface costs no scan of the whole surface.
  CappedDistance(const PointCloud& surface, float cap)
      : index_(surface, cap / (NearestNeighbours::kMaxRing * NearestNeighbours::kCoarse)), cap_(cap) {}

  /// The `share` quantile of the distances from `points`, turned, to the surface; cap_ when
  /// at least that share lies farther. Checks a first slice of the points and gives up early
  /// when it already misses `give_up` (most turns are far from symmetric).
  float quantile(const PointCloud& points, const Pose& turn, float share, float give_up) {
    std::vector<float> d;
    d.reserve(points.size());
    const std::size_t slice = std::min<std::size_t>(points.size(), 1500);
    for (std::size_t i = 0; i < points.size(); ++i) {
      if (i == slice && quantileOf(d, share) > give_up) return cap_;
      d.push_back(nearest(turn.R * points[i] + turn.t));
    }
    return quantileOf(d, share);
  }

 private:
  float nearest(const Eigen::Vector3f& q) const {
    float d_sqr = 0.f;
    return index_.nearestWithin(q, cap_, d_sqr) < 0 ? cap_ : std::sqrt(d_sqr);
  }
  static float quantileOf(std::vector<float> d, float share) {
    if (d.empty()) return 0.f;
    const auto k = d.begin() + static_cast<std::ptrdiff_t>(share * static_cast<float>(d.size() - 1));
    std::nth_element(d.begin(), k, d.end());
    return *k;
  }
  NearestNeighbours index_;
  float cap_;
};

}  // namespace

Pose NearSymmetry::transform() const {
  Pose p;
  p.R = Eigen::AngleAxisf(angle_deg * static_cast<float>(M_PI) / 180.f, axis.normalized()).toRotationMatrix();
  p.t = point - p.R * point;
  return p;
}

std::string describe(const NearSymmetry& s) {
  return fmt::format("{:.0f} deg about ({:.2f}, {:.2f}, {:.2f}) through ({:.1f}, {:.1f}, {:.1f}) mm, off by {:.1f} mm",
                     s.angle_deg, s.axis.x(), s.axis.y(), s.axis.z(), 1e3f * s.point.x(), 1e3f * s.point.y(),
                     1e3f * s.point.z(), 1e3f * s.deviation_m);
}

namespace {

/// Turns by `angles` about the principal and model axes whose deviation lies in
/// (from_m, to_m], the closer of two that are one turn, sorted by deviation.
std::vector<NearSymmetry> findTurns(const Mesh& mesh, const std::vector<float>& angles, float from_m, float to_m,
                                    int max_count) {
  std::vector<NearSymmetry> found;
  if (to_m <= 0.f || to_m <= from_m || mesh.faces.empty() || max_count <= 0) return found;
  const PointCloud a = sampleSurface(mesh, kSamples, 1u), b = sampleSurface(mesh, kSamples, 2u);
  if (a.empty()) return found;
  Eigen::Vector3f mean = Eigen::Vector3f::Zero();
  for (const auto& p : a) mean += p;
  mean /= static_cast<float>(a.size());
  Eigen::Matrix3f cov = Eigen::Matrix3f::Zero();
  for (const auto& p : a) cov += (p - mean) * (p - mean).transpose();
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3f> eig(cov);

  // Axes: the principal axes through the surface's centroid, then the model's axes through
  // the box centre (a carton with a spout has its centroid off the prism's axis).
  std::vector<std::pair<Eigen::Vector3f, Eigen::Vector3f>> axes;  // direction, point
  for (int i = 2; i >= 0; --i) axes.emplace_back(eig.eigenvectors().col(i).normalized(), mean);
  for (int i = 0; i < 3; ++i) axes.emplace_back(Eigen::Vector3f::Unit(i), mesh.bboxCentre());

  // Distances are searched up to the tolerance plus a few sampling spacings (the floor).
  const float spacing = mesh.diameter / std::sqrt(static_cast<float>(kSamples));
  CappedDistance distance(b, to_m + 4.f * spacing);
  const float floor = distance.quantile(a, Pose{}, kQuantile, 1e9f);

  for (const auto& [axis, point] : axes) {
    for (const float angle : angles) {
      NearSymmetry s;
      s.axis = axis;
      s.point = point;
      s.angle_deg = angle;
      s.deviation_m = std::max(0.f, distance.quantile(a, s.transform(), kQuantile, to_m + floor) - floor);
      if (s.deviation_m > to_m) continue;
      // The same turn found twice (a principal axis near a model axis): keep the closer fit.
      const Pose t = s.transform();
      const Eigen::Vector3f c = mesh.bboxCentre();
      const auto same = std::find_if(found.begin(), found.end(), [&](const NearSymmetry& o) {
        const Pose u = o.transform();
        return (t.R - u.R).norm() < 0.25f && ((t.R * c + t.t) - (u.R * c + u.t)).norm() < to_m;
      });
      if (same == found.end())
        found.push_back(s);
      else if (s.deviation_m < same->deviation_m)
        *same = s;
    }
  }
  // Dropped only now: a turn within from_m may have been the closer twin of one beyond it.
  found.erase(std::remove_if(found.begin(), found.end(), [&](const NearSymmetry& s) { return s.deviation_m <= from_m; }),
              found.end());
  std::stable_sort(found.begin(), found.end(),
                   [](const NearSymmetry& x, const NearSymmetry& y) { return x.deviation_m < y.deviation_m; });
  if (found.size() > static_cast<std::size_t>(max_count)) found.resize(static_cast<std::size_t>(max_count));
  return found;
}

}  // namespace

std::vector<NearSymmetry> findNearSymmetries(const Mesh& mesh, float tolerance_m, int max_count) {
  return findTurns(mesh, {kAngles.begin(), kAngles.end()}, -1.f, tolerance_m, max_count);
}

std::vector<NearSymmetry> exactSymmetries(const Mesh& mesh, float tolerance_m) {
  std::vector<NearSymmetry> exact;
  if (mesh.vertices.empty() || !(tolerance_m > 0.f)) return exact;
  const NearestNeighbours vertices(mesh.vertices, tolerance_m);
  const bool coloured = mesh.colours.size() == mesh.vertices.size();
  for (const NearSymmetry& s : findNearSymmetries(mesh, 0.01f * mesh.diameter)) {
    const Pose turn = s.transform();
    bool maps = true;
    std::vector<int> near;
    for (std::size_t i = 0; maps && i < mesh.vertices.size(); ++i) {
      // Any vertex there of its colour: a painted mesh repeats a corner's vertex per face.
      near.clear();
      vertices.within(turn.R * mesh.vertices[i] + turn.t, tolerance_m, near);
      maps = std::any_of(near.begin(), near.end(), [&](int j) {
        return !coloured || (mesh.colours[i] - mesh.colours[static_cast<std::size_t>(j)]).cwiseAbs().maxCoeff() <= 0.1f;
      });
    }
    if (maps) exact.push_back(s);
  }
  return exact;
}

std::optional<NearSymmetry> revolutionAxis(const std::vector<NearSymmetry>& symmetries) {
  // The search turns about a few fixed axes, so the turns of one axis share its direction and
  // point exactly (bank files keep them bit for bit); a little slack costs nothing.
  auto sameAxis = [](const NearSymmetry& a, const NearSymmetry& b) {
    return std::abs(a.axis.normalized().dot(b.axis.normalized())) > 0.9999f && (a.point - b.point).norm() < 1e-5f;
  };
  auto isAny = [](float angle, std::initializer_list<float> of) {
    return std::any_of(of.begin(), of.end(), [&](float a) { return std::abs(angle - a) < 0.5f; });
  };
  // A turn of a sixth and one of a quarter about the same axis make a turn of a twelfth: at
  // least 12-fold, which no mesh is short of a body of revolution. Checked this way because a
  // bank keeps only its few closest near-symmetries, which for a can include its half-turns
  // end for end, crowding out some of the turns about its axis.
  for (const NearSymmetry& s : symmetries) {
    bool sixth = false, quarter = false;
    for (const NearSymmetry& o : symmetries) {
      if (!sameAxis(s, o)) continue;
      sixth = sixth || isAny(o.angle_deg, {60.f, 120.f, 240.f, 300.f});
      quarter = quarter || isAny(o.angle_deg, {90.f, 270.f});
    }
    if (sixth && quarter) return s;
  }
  return std::nullopt;
}

std::vector<NearSymmetry> findLookAlikeTurns(const Mesh& mesh, float from_m, float to_m, int max_count) {
  return findTurns(mesh, {180.f}, std::max(0.f, from_m), to_m, max_count);
}

}  // namespace vkpose
