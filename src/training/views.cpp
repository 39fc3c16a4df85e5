#include "vkpose/bank.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <numbers>
#include <set>
#include <utility>

#include <Eigen/Geometry>
#include <fmt/format.h>

#include "vkpose/error.hpp"

namespace vkpose {

SteppedRange parseSteppedRange(const std::string& text, const std::string& what) {
  SteppedRange r;
  float a = 0.f, b = 0.f, s = 0.f;
  char tail = 0;
  if (std::sscanf(text.c_str(), "%f:%f:%f%c", &a, &b, &s, &tail) == 3) {
    r = {a, b, s};
  } else if (std::sscanf(text.c_str(), "%f%c", &a, &tail) == 1) {
    r = {a, a, 1.f};
  } else {
    throw InputError(fmt::format("{} '{}': expected FROM:TO:STEP or one value", what, text));
  }
  if (!std::isfinite(r.from) || !std::isfinite(r.to) || !std::isfinite(r.step) || r.step <= 0.f || r.to < r.from)
    throw InputError(fmt::format("{} '{}': need FROM <= TO and STEP > 0", what, text));
  if (r.values().size() > 10000) throw InputError(fmt::format("{} '{}': more than 10000 values", what, text));
  return r;
}

namespace {
/// Before values(): a range of NaN or of too many steps (a damaged bank's) would make it cast
/// NaN or a huge count to int (undefined; found by fuzz_bank).
void checkRange(const SteppedRange& r, const char* what) {
  if (!std::isfinite(r.from) || !std::isfinite(r.to) || !std::isfinite(r.step) || r.step <= 0.f || r.to < r.from)
    throw InputError(fmt::format("{} {}:{}:{}: need finite FROM <= TO and STEP > 0", what, r.from, r.to, r.step));
  if ((static_cast<double>(r.to) - r.from) / r.step > 10000.0)
    throw InputError(fmt::format("{} {}:{}:{}: more than 10000 values", what, r.from, r.to, r.step));
}
}  // namespace

void validateViewSampling(const ViewSamplingParams& p) {
  if (p.viewpoints < 1 || p.viewpoints > 100000)
    throw InputError(fmt::format("views: {} viewpoints; use 1 to 100000", p.viewpoints));
  checkRange(p.radii, "radii");
  checkRange(p.inplane_deg, "in-plane rotations");
  if (!(p.full_turn_within_deg >= 0.f && p.full_turn_within_deg <= 90.f))
    throw InputError(fmt::format("the whole turn in-plane within {} degrees of the top: use 0 to 90",
                                 p.full_turn_within_deg));
  if (p.full_turn_within_deg > 0.f && fullTurnStep(p.inplane_deg) < 0.1f)
    throw InputError(fmt::format("in-plane step {} degrees: the whole turn needs a step of 0.1 degrees or more",
                                 p.inplane_deg.step));
  for (float r : p.radii.values())
    if (!(r >= 0.05f && r <= 6.f)) throw InputError(fmt::format("radii: {} m is outside 0.05 to 6 m", r));
  // Up to a full turn either way, so that a range can be centred on 180 degrees (120:240:10)
  // for a mesh modelled upside down, whose "up" then points down in the image.
  for (float a : p.inplane_deg.values())
    if (!(a >= -360.f && a <= 360.f))
      throw InputError(fmt::format("in-plane rotation {} degrees is outside -360 to 360", a));
  const auto checkUnit = [](const Eigen::Vector3f& up, const char* what) {
    if (!up.allFinite() || std::abs(up.norm() - 1.f) > 1e-3f)
      throw InputError(fmt::format("{} ({}, {}, {}) is not a unit vector", what, up.x(), up.y(), up.z()));
  };
  checkUnit(p.up, "up axis");
  if (p.other_ups.size() > 5)
    throw InputError(fmt::format("{} other resting poses: an object rests on at most six sides", p.other_ups.size()));
  for (const Eigen::Vector3f& up : p.other_ups) checkUnit(up, "the up axis of another resting pose");
  if (p.full_sphere && !p.other_ups.empty())
    throw InputError("other resting poses with the full sphere: it already sees every side");
}

namespace {
/// The rotation that turns +z into `up` (the sphere's pole into the object's up axis).
Eigen::Matrix3f poleTo(const Eigen::Vector3f& up) {
  return Eigen::Quaternionf::FromTwoVectors(Eigen::Vector3f::UnitZ(), up.normalized()).toRotationMatrix();
}
}  // namespace

std::vector<Eigen::Vector3f> sphereViewpoints(int count, bool full_sphere) {
  // Fibonacci lattice: equal-area bands in z, golden-angle steps in azimuth. On the
  // hemisphere z runs from 1 (pole) down towards 0, never reaching the horizon exactly.
  std::vector<Eigen::Vector3f> dirs;
  const double golden = std::numbers::pi * (3.0 - std::sqrt(5.0));
  for (int i = 0; i < count; ++i) {
    const double u = (i + 0.5) / count;
    const double z = full_sphere ? 1.0 - 2.0 * u : 1.0 - u;
    const double rho = std::sqrt(std::max(0.0, 1.0 - z * z));
    const double phi = golden * i;
    dirs.emplace_back(static_cast<float>(rho * std::cos(phi)), static_cast<float>(rho * std::sin(phi)),
                      static_cast<float>(z));
  }
  return dirs;
}

TrainingView lookAtView(const Eigen::Vector3f& direction, const Eigen::Vector3f& centre, float distance,
                        float inplane_deg, const Eigen::Vector3f& object_up) {
  const Eigen::Vector3f z_cam = -direction.normalized();  // optical axis, in object coordinates
  Eigen::Vector3f up = object_up.normalized();
  if (std::abs(z_cam.dot(up)) > 0.999f) up = poleTo(object_up) * Eigen::Vector3f::UnitY();
  // Camera y points down in the image, so it is minus "up" made orthogonal to the axis.
  const Eigen::Vector3f y_cam = -(up - up.dot(z_cam) * z_cam).normalized();
  const Eigen::Vector3f x_cam = y_cam.cross(z_cam);
  Eigen::Matrix3f R_obj_to_cam;
  R_obj_to_cam.row(0) = x_cam.transpose();
  R_obj_to_cam.row(1) = y_cam.transpose();
  R_obj_to_cam.row(2) = z_cam.transpose();
  const float a = inplane_deg * static_cast<float>(std::numbers::pi / 180.0);
  const Eigen::Matrix3f Rz = Eigen::AngleAxisf(a, Eigen::Vector3f::UnitZ()).toRotationMatrix();
  TrainingView v;
  v.R = Rz * R_obj_to_cam;
  // The centre lands on the optical axis at `distance`: R * centre + t = (0, 0, distance).
  v.t = Eigen::Vector3f(0.f, 0.f, distance) - v.R * centre;
  v.distance = distance;
  v.inplane_deg = inplane_deg;
  v.up = object_up.normalized();
  return v;
}

float fullTurnStep(const SteppedRange& inplane) {
  return inplane.values().size() > 1 ? inplane.step : kFullTurnSingleAngleStepDeg;
}

std::vector<float> fullTurnInPlane(const SteppedRange& inplane) {
  checkRange(inplane, "in-plane rotations");
  // On the range's own grid (so the turn holds its angles), from half a turn below its middle.
  const float step = fullTurnStep(inplane);
  const float lowest = 0.5f * (inplane.from + inplane.to) - 180.f;
  const float start = inplane.from - step * std::floor((inplane.from - lowest) / step + 1e-4f);
  std::vector<float> out;
  for (int i = 0; start + static_cast<float>(i) * step < lowest + 360.f - 1e-3f; ++i)
    out.push_back(start + static_cast<float>(i) * step);
  return out;
}

std::vector<TrainingView> sampleViews(const ViewSamplingParams& params, const Eigen::Vector3f& centre) {
  validateViewSampling(params);
  const auto dirs = sphereViewpoints(params.viewpoints, params.full_sphere);
  const auto radii = params.radii.values();
  const auto range = params.inplane_deg.values();
  const auto whole_turn = fullTurnInPlane(params.inplane_deg);
  // The lattice's pole is +z: a viewpoint's z is the cosine of its angle from the top.
  const float full_turn_min_z =
      params.full_turn_within_deg > 0.f ? std::cos(params.full_turn_within_deg * std::numbers::pi_v<float> / 180.f)
                                        : 2.f;
  std::vector<Eigen::Vector3f> ups{params.up};
  ups.insert(ups.end(), params.other_ups.begin(), params.other_ups.end());
  std::vector<TrainingView> views;
  views.reserve(ups.size() * dirs.size() * radii.size() * std::max(range.size(), whole_turn.size()));
  for (std::size_t k = 0; k < ups.size(); ++k) {
    const Eigen::Matrix3f turn = poleTo(ups[k]);
    for (std::size_t i = 0; i < dirs.size(); ++i) {
      const auto& angles = dirs[i].z() >= full_turn_min_z ? whole_turn : range;
      for (float r : radii)
        for (float a : angles) {
          auto v = lookAtView(turn * dirs[i], centre, r, a, ups[k]);
          v.viewpoint = static_cast<int>(k * dirs.size() + i);
          views.push_back(v);
        }
    }
  }
  return views;
}

std::vector<TrainingView> dropTurnsShownAlready(const std::vector<TrainingView>& views, const SteppedRange& inplane,
                                                const std::vector<NearSymmetry>& symmetries, float tolerance_deg) {
  const auto within = [&](float a) { return a >= inplane.from - 1e-3f && a <= inplane.to + 1e-3f; };
  // A view's picture hangs on its rotation alone (its radii share it): one per viewpoint and turn.
  const auto key = [](const TrainingView& v) { return std::pair(v.viewpoint, std::lround(v.inplane_deg * 1000.f)); };
  std::map<std::pair<int, long>, Eigen::Matrix3f> range, added;
  for (const TrainingView& v : views) (within(v.inplane_deg) ? range : added).emplace(key(v), v.R);
  std::vector<Eigen::Quaternionf> shown;
  shown.reserve(range.size());
  for (const auto& [k, R] : range) shown.emplace_back(R);
  // A pose R and R * S show the same picture when S is a near-symmetry (and so is its inverse).
  std::vector<Eigen::Matrix3f> turns{Eigen::Matrix3f::Identity()};
  for (const NearSymmetry& s : symmetries) {
    const Eigen::Matrix3f S = s.transform().R;
    turns.push_back(S);
    turns.push_back(S.transpose());
  }
  const float min_dot = std::cos(0.5f * tolerance_deg * std::numbers::pi_v<float> / 180.f);
  std::set<std::pair<int, long>> repeated;
  for (const auto& [k, R] : added)
    for (const Eigen::Matrix3f& S : turns) {
      const Eigen::Quaternionf q(Eigen::Matrix3f(R * S));
      if (std::any_of(shown.begin(), shown.end(), [&](const Eigen::Quaternionf& b) {
            return std::abs(b.dot(q)) >= min_dot;
          })) {
        repeated.insert(k);
        break;
      }
    }
  std::vector<TrainingView> out;
  out.reserve(views.size());
  for (const TrainingView& v : views)
    if (!repeated.contains(key(v))) out.push_back(v);
  return out;
}

std::vector<TrainingView> viewsAbove(const std::vector<TrainingView>& views, const Eigen::Vector3f& centre,
                                     float max_polar_deg) {
  if (!(max_polar_deg > 0.f && max_polar_deg <= 180.f))
    throw InputError(fmt::format("the largest angle from the top must be in (0, 180] degrees, not {}", max_polar_deg));
  const float min_cos = std::cos(max_polar_deg * std::numbers::pi_v<float> / 180.f);
  std::vector<TrainingView> out;
  for (const TrainingView& v : views) {
    const Eigen::Vector3f camera = -(v.R.transpose() * v.t);  // the camera's centre, object frame
    if ((camera - centre).normalized().dot(v.up) >= min_cos - 1e-6f) out.push_back(v);
  }
  return out;
}

}  // namespace vkpose
