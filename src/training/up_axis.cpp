// The object's up axis, found from its mesh: which end it stands on (findUpAxis, bank.hpp), the
// other poses it rests in, and what training makes of them (planTraining).
#include <algorithm>
#include <array>
#include <cmath>

#include <Eigen/Geometry>
#include <fmt/format.h>
#include <opencv2/imgproc.hpp>

#include "vkpose/bank.hpp"
#include "vkpose/error.hpp"

namespace vkpose {

namespace {

/// An axis earlier in the conventions' order wins if its base is at least this share of the
/// broadest: a cup keeps +z (its base 44 % of its footprint) against its rim (70 %), but a carton
/// modelled with +y up does not stand on its side (+z, 22 %) when its base (61 %) is there.
constexpr float kRivalShare = 0.5f;

constexpr std::array<const char*, 6> kAxisNames{"+z", "-z", "+y", "-y", "+x", "-x"};

Eigen::Vector3f axisOf(int i) {
  const int axis = 2 - i / 2;  // z, y, x
  return (i % 2 == 0 ? 1.f : -1.f) * Eigen::Vector3f::Unit(axis);
}

/// The centre of mass of the solid the mesh bounds (signed tetrahedra from the origin); the
/// vertex mean when the mesh encloses no volume (an open surface), which is biased towards
/// finely tessellated parts but still inside the object.
Eigen::Vector3f centreOfMass(const Mesh& mesh) {
  double volume = 0;
  Eigen::Vector3d moment = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3i& f : mesh.faces) {
    const Eigen::Vector3d a = mesh.vertices[f[0]].cast<double>(), b = mesh.vertices[f[1]].cast<double>(),
                          c = mesh.vertices[f[2]].cast<double>();
    const double v = a.dot(b.cross(c)) / 6.0;
    volume += v;
    moment += v * (a + b + c) / 4.0;
  }
  const double extent = std::max<double>(mesh.diameter, 1e-6);
  if (std::abs(volume) < 1e-6 * extent * extent * extent) return mesh.centroid;
  return (moment / volume).cast<float>();
}

float hullArea(std::vector<cv::Point2f>& points, std::vector<cv::Point2f>& hull) {
  hull.clear();
  if (points.size() < 3) return 0.f;
  cv::convexHull(points, hull);
  return hull.size() < 3 ? 0.f : static_cast<float>(cv::contourArea(hull));
}

/// 2-D coordinates across `direction` (a rotation that takes it to +z).
Eigen::Matrix3f acrossOf(const Eigen::Vector3f& direction) {
  return Eigen::Quaternionf::FromTwoVectors(direction, Eigen::Vector3f::UnitZ()).toRotationMatrix();
}

/// How the object rests with `axis` roughly up. Scanned meshes are not modelled exactly
/// axis-aligned (a base a few degrees off the axis touches a table plane perpendicular to the
/// axis along one edge only), so the base is searched among the directions within 15 degrees
/// of the axis: the one with the broadest contact on which the centre of mass stands.
RestingCandidate restingOn(const Mesh& mesh, const Eigen::Vector3f& axis, const Eigen::Vector3f& com) {
  RestingCandidate best;
  best.up = axis;
  best.margin_m = -INFINITY;
  const Eigen::Matrix3f across_axis = acrossOf(axis);
  std::vector<cv::Point2f> all, hull;
  for (const auto& v : mesh.vertices) {
    const Eigen::Vector3f p = across_axis * v;
    all.emplace_back(p.x(), p.y());
  }
  const float footprint = hullArea(all, hull);
  if (!(footprint > 0.f)) return best;
  // Any direction perpendicular to the axis, to tilt it by.
  const Eigen::Vector3f side = across_axis.transpose() * Eigen::Vector3f::UnitX();
  std::vector<cv::Point2f> touching;
  for (const float tilt_deg : {0.f, 1.f, 2.f, 3.f, 4.f, 6.f, 8.f, 10.f, 12.f, 15.f}) {
    const int turns = tilt_deg == 0.f ? 1 : 24;
    for (int k = 0; k < turns; ++k) {
      const Eigen::Vector3f tilt_axis = Eigen::AngleAxisf(static_cast<float>(k) * 2.f * EIGEN_PI / 24.f, axis) * side;
      const Eigen::Vector3f up = Eigen::AngleAxisf(tilt_deg * EIGEN_PI / 180.f, tilt_axis) * axis;
      float low = INFINITY, high = -INFINITY;
      for (const auto& v : mesh.vertices) {
        const float h = v.dot(up);
        low = std::min(low, h);
        high = std::max(high, h);
      }
      // A base is flat to its tessellation and a scan's noise: within 1.5 % of the height.
      const float band = std::max(0.001f, 0.015f * (high - low));
      const Eigen::Matrix3f across = acrossOf(up);
      touching.clear();
      for (const auto& v : mesh.vertices)
        if (v.dot(up) < low + band) {
          const Eigen::Vector3f p = across * v;
          touching.emplace_back(p.x(), p.y());
        }
      const float contact = hullArea(touching, hull);
      const Eigen::Vector3f m = across * com;
      const float margin = hull.size() >= 3
                               ? static_cast<float>(cv::pointPolygonTest(hull, cv::Point2f(m.x(), m.y()), true))
                               : -1.f;
      const float support = contact / footprint;
      // A stable base beats an unstable one; among equals, the broader.
      const bool better = (margin > 0.f) != (best.margin_m > 0.f) ? margin > 0.f : support > best.support;
      if (better) {
        best.support = support;
        best.margin_m = margin;
        best.tilt_deg = tilt_deg;
      }
    }
  }
  return best;
}

}  // namespace

bool RestingCandidate::stands() const { return support >= 0.15f && margin_m > 0.f; }

Eigen::Vector3f parseUpAxis(const std::string& text) {
  for (int i = 0; i < 6; ++i)
    if (text == kAxisNames[i]) return axisOf(i);
  throw InputError(fmt::format("up axis '{}': expected auto, +x, -x, +y, -y, +z or -z", text));
}

std::string upAxisName(const Eigen::Vector3f& up) {
  for (int i = 0; i < 6; ++i)
    if ((up - axisOf(i)).norm() < 1e-4f) return kAxisNames[i];
  return fmt::format("({:.3f}, {:.3f}, {:.3f})", up.x(), up.y(), up.z());
}

UpAxisChoice findUpAxis(const Mesh& mesh) {
  if (mesh.vertices.empty() || mesh.faces.empty()) throw InputError("the up axis of an empty mesh");
  const Eigen::Vector3f com = centreOfMass(mesh);
  UpAxisChoice choice;
  for (int i = 0; i < 6; ++i) choice.candidates.push_back(restingOn(mesh, axisOf(i), com));
  const auto describe = [](const RestingCandidate& c) {
    return fmt::format("{} up: a base of {:.0f}% of its footprint{}{}", upAxisName(c.up), 100.f * c.support,
                       c.tilt_deg > 0.f ? fmt::format(", {:.0f} degrees off the axis", c.tilt_deg) : "",
                       c.margin_m > 0.f ? "" : ", tips over");
  };
  float broadest = 0.f;
  for (const RestingCandidate& c : choice.candidates)
    if (c.stands()) broadest = std::max(broadest, c.support);
  for (const RestingCandidate& c : choice.candidates)
    if (c.stands() && c.support >= kRivalShare * broadest) {
      choice.up = c.up;
      choice.found = true;
      choice.reason = describe(c);
      if (c.up != choice.candidates.front().up)
        choice.reason += fmt::format(" (+z up: a base of {:.0f}%{})", 100.f * choice.candidates.front().support,
                                     choice.candidates.front().margin_m > 0.f ? "" : ", tips over");
      return choice;
    }
  choice.reason = fmt::format("no end of the object is a stable base (+z up: {:.0f}%); assuming +z: pass --up to set it",
                              100.f * choice.candidates.front().support);
  return choice;
}

std::vector<Eigen::Vector3f> otherRestingUps(const UpAxisChoice& choice, const Eigen::Vector3f& up,
                                             const std::vector<NearSymmetry>& symmetries) {
  // Views about u and about a turn of u look the same when the turn maps the surface onto
  // itself: the object turned rests on u's side showing the same shape. Either direction of
  // the turn, in case the list holds one of a pair.
  constexpr float kSame = 0.99f;  // within 8 degrees
  const auto covered = [&](const Eigen::Vector3f& u, const std::vector<Eigen::Vector3f>& seen) {
    for (const Eigen::Vector3f& s : seen) {
      if (u.dot(s) > kSame) return true;
      for (const NearSymmetry& sym : symmetries) {
        const Eigen::Matrix3f R = sym.transform().R;
        if ((R * u).dot(s) > kSame || (R.transpose() * u).dot(s) > kSame) return true;
      }
    }
    return false;
  };
  std::vector<Eigen::Vector3f> seen{up.normalized()}, out;
  for (const RestingCandidate& c : choice.candidates) {
    if (!c.stands() || covered(c.up, seen)) continue;
    seen.push_back(c.up);
    out.push_back(c.up);
  }
  return out;
}

bool trainsOtherRestingPoses(const std::string& resting, float diameter_m, float nearest_distance_m) {
  if (resting == "all") return true;
  if (resting == "up") return false;
  if (resting == "auto") return isSmallPart(diameter_m) || nearest_distance_m < kPileDistanceM;
  throw InputError(fmt::format("resting: '{}' is none of auto, all, up", resting));
}

TrainingPlan planTraining(const Mesh& mesh, TrainingParams& params, bool auto_up, const std::string& resting,
                          float max_view_angle_deg, std::optional<float> full_turn_within_deg) {
  TrainingPlan plan;
  const bool trains_others =  // throws first on a bad name
      trainsOtherRestingPoses(resting, mesh.diameter, params.views.radii.low());
  plan.found = findUpAxis(mesh);
  if (auto_up) params.views.up = plan.found.up;
  params.views.other_ups.clear();
  const std::vector<NearSymmetry> symmetries =
      findNearSymmetries(mesh, params.near_symmetry_tolerance * mesh.diameter);
  if (!params.views.full_sphere) {
    plan.other_ups = otherRestingUps(plan.found, params.views.up, symmetries);
    if (trains_others) params.views.other_ups = plan.other_ups;
  }
  params.views.full_turn_within_deg = full_turn_within_deg.value_or(trains_others ? kPileFullTurnWithinDeg : 0.f);
  // The whole turn's views that a view of the range, or a near-symmetry of one, shows within a
  // step already: a body of revolution seen down its axis gains nothing from them.
  plan.views = viewsAbove(dropTurnsShownAlready(sampleViews(params.views, mesh.bboxCentre()), params.views.inplane_deg,
                                                symmetries, fullTurnStep(params.views.inplane_deg)),
                          mesh.bboxCentre(), max_view_angle_deg);
  if (plan.views.empty())
    throw InputError(fmt::format("no viewpoint lies within {} degrees of the top", max_view_angle_deg));
  return plan;
}

}  // namespace vkpose
