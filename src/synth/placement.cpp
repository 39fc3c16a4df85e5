// Placements for synthetic scenes: stable resting orientations, box overlap tests, a camera
// over the table, drop-and-settle in a bin, and the table under given poses.
#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>

#include "synth/placement.hpp"
#include "vkpose/bank.hpp"
#include "vkpose/error.hpp"
#include "vkpose/geometry.hpp"

namespace vkpose {

namespace {

constexpr float kPi = std::numbers::pi_v<float>;

float radians(float degrees) { return degrees * kPi / 180.f; }

Eigen::Matrix3f yaw(float angle) { return Eigen::AngleAxisf(angle, Eigen::Vector3f::UnitZ()).toRotationMatrix(); }

/// Lowest z of the mesh's vertices turned by R.
float lowestZ(const Mesh& mesh, const Eigen::Matrix3f& R) {
  const Eigen::RowVector3f row = R.row(2);
  float z = std::numeric_limits<float>::max();
  for (const auto& v : mesh.vertices) z = std::min(z, row.dot(v.transpose()));
  return z;
}

/// Half extents along world x, y, z of a box.
Eigen::Vector3f worldHalfExtent(const OrientedBox& b) { return b.axes.cwiseAbs() * b.half; }

bool clear(const OrientedBox& box, const std::vector<OrientedBox>& others, float gap) {
  return std::none_of(others.begin(), others.end(), [&](const OrientedBox& o) { return boxesIntersect(box, o, gap); });
}

const RestingOrientation& pickResting(const std::vector<RestingOrientation>& rest, std::mt19937& rng) {
  float total = 0.f;
  for (const auto& r : rest) total += r.weight;
  float u = uniform(rng, 0.f, total);
  for (const auto& r : rest) {
    if (u < r.weight) return r;
    u -= r.weight;
  }
  return rest.back();
}

/// Table: a point the camera sees well inside the image, a stable orientation, a random yaw.
std::optional<Pose> tryOnTable(const Mesh& mesh, const std::vector<RestingOrientation>& rest, const Camera& camera,
                               const Pose& world_T_camera, const PlacementParams& params, std::mt19937& rng) {
  const float m = params.image_margin;
  const float u = uniform(rng, m, 1.f - m) * static_cast<float>(camera.width);
  const float v = uniform(rng, m, 1.f - m) * static_cast<float>(camera.height);
  const Eigen::Vector3f ray_cam = camera.ray(u, v);
  const Eigen::Vector3f ray = world_T_camera.R * ray_cam, origin = world_T_camera.t;
  const RestingOrientation& r = pickResting(rest, rng);
  const float turn = uniform(rng, 0.f, 2.f * kPi);
  if (ray.z() >= -1e-3f) return std::nullopt;  // the ray does not reach the table
  const Eigen::Vector3f spot = origin - (origin.z() / ray.z()) * ray;
  Pose p;
  p.R = yaw(turn) * r.R;
  const Eigen::Vector3f centre = p.R * mesh.bboxCentre();
  p.t = Eigen::Vector3f(spot.x() - centre.x(), spot.y() - centre.y(), r.lift_m);
  return p;
}

/// Bin: a random orientation over a random point of the bin, lowered onto the floor or the
/// objects below, whichever it meets first (the lowest height at which its box is clear).
std::optional<Pose> tryInBin(const Mesh& mesh, const std::vector<RestingOrientation>& rest,
                             const std::vector<OrientedBox>& placed, const PlacementParams& params, std::mt19937& rng) {
  // A resting orientation with a random yaw, tipped by up to max_tilt_deg about a random
  // horizontal axis: parts in a bin lie on a side, leaning on each other. Fully random
  // rotations would stack their (then loose) boxes into towers.
  const RestingOrientation& r = pickResting(rest, rng);
  const float turn = uniform(rng, 0.f, 2.f * kPi), tip_axis = uniform(rng, 0.f, 2.f * kPi);
  const float tip = radians(uniform(rng, 0.f, params.bin_max_tilt_deg));
  Pose p;
  p.R = Eigen::AngleAxisf(tip, Eigen::Vector3f(std::cos(tip_axis), std::sin(tip_axis), 0.f)).toRotationMatrix() *
        yaw(turn) * r.R;
  const OrientedBox at_origin = orientedBox(mesh, p);
  const Eigen::Vector3f ext = worldHalfExtent(at_origin);
  const Eigen::Vector2f room = 0.5f * params.bin_inner_m - ext.head<2>() - Eigen::Vector2f::Constant(params.gap_m);
  const float x = uniform(rng, -1.f, 1.f), y = uniform(rng, -1.f, 1.f);
  if (room.x() <= 0.f || room.y() <= 0.f) return std::nullopt;  // does not fit in the bin this way round
  p.t = Eigen::Vector3f(x * room.x(), y * room.y(), 0.f) - Eigen::Vector3f(at_origin.centre.x(), at_origin.centre.y(), 0.f);
  p.t.z() = -lowestZ(mesh, p.R) + params.gap_m;
  for (; p.t.z() + at_origin.centre.z() - ext.z() <= params.max_pile_m; p.t.z() += params.drop_step_m) {
    // Drop: the lowest clear height from the floor up is where it comes to rest.
    if (clear(orientedBox(mesh, p), placed, params.gap_m)) return p;
  }
  return std::nullopt;
}

}  // namespace



OrientedBox orientedBox(const Mesh& mesh, const Pose& world_T_object) {
  OrientedBox b;
  b.axes = world_T_object.R;
  b.centre = world_T_object.R * mesh.bboxCentre() + world_T_object.t;
  b.half = 0.5f * (mesh.bbox_max - mesh.bbox_min);
  return b;
}

bool boxesIntersect(const OrientedBox& a, const OrientedBox& b, float gap_m) {
  // Separating axes: the 3 + 3 face normals and the 9 edge cross products (Gottschalk et al.).
  const Eigen::Vector3f d = b.centre - a.centre;
  const auto separated = [&](const Eigen::Vector3f& axis) {
    const float n = axis.norm();
    if (n < 1e-6f) return false;  // parallel edges: the face axes decide
    const Eigen::Vector3f l = axis / n;
    const float ra = (a.axes.transpose() * l).cwiseAbs().dot(a.half);
    const float rb = (b.axes.transpose() * l).cwiseAbs().dot(b.half);
    return std::abs(d.dot(l)) > ra + rb + gap_m;
  };
  for (int i = 0; i < 3; ++i)
    if (separated(a.axes.col(i)) || separated(b.axes.col(i))) return false;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      if (separated(a.axes.col(i).cross(b.axes.col(j)))) return false;
  return true;
}

std::vector<RestingOrientation> restingOrientations(const Mesh& mesh) {
  if (mesh.vertices.empty() || mesh.faces.empty()) throw InputError("resting orientations of an empty mesh");
  // The object rests where training says it stands (findUpAxis: a base of at least 15 % of its
  // footprint with the centre of mass over it), so that a scene holds the poses a bank trained
  // with --resting all covers. An earlier test of its own (the vertex centroid within 1 % of
  // the diameter of the contact points' hull) also let a milk jug balance on its cap, a pose no
  // bank trains for.
  const UpAxisChoice choice = findUpAxis(mesh);
  std::vector<RestingOrientation> out, all;
  // The old order (x, y, z; the face down before its opposite), so that the draws of meshes
  // whose stable faces did not change come out as before.
  for (int axis = 0; axis < 3; ++axis)
    for (const float sign : {-1.f, 1.f}) {
      const Eigen::Vector3f down = sign * Eigen::Vector3f::Unit(axis);
      RestingOrientation r;
      r.R = Eigen::Quaternionf::FromTwoVectors(down, -Eigen::Vector3f::UnitZ()).toRotationMatrix();
      const float low = lowestZ(mesh, r.R);
      r.lift_m = -low;
      r.weight = 1.f / std::max(1e-3f, (r.R * mesh.centroid).z() - low);
      all.push_back(r);
      for (const RestingCandidate& c : choice.candidates)
        if (c.up.dot(-down) > 0.999f && c.stands()) out.push_back(r);
    }
  if (out.empty()) {
    for (auto& r : all) r.weight = 1.f;
    return all;
  }
  return out;
}

Pose lookDownAt(const Eigen::Vector3f& target, float height_m, float tilt_rad, float azimuth_rad, float roll_rad) {
  const Eigen::Vector3f side(std::cos(azimuth_rad), std::sin(azimuth_rad), 0.f);
  const Eigen::Vector3f position = target + height_m * std::tan(tilt_rad) * side + Eigen::Vector3f(0.f, 0.f, height_m);
  const Eigen::Vector3f forward = (target - position).normalized();
  // Image up is the far side: the horizontal direction from the camera to the target, made
  // perpendicular to the optical axis (well defined even looking straight down).
  const Eigen::Vector3f away = -side;
  const Eigen::Vector3f down = -(away - away.dot(forward) * forward).normalized();
  const Eigen::Vector3f right = down.cross(forward);
  Eigen::Matrix3f world_R_camera;
  world_R_camera << right, down, forward;
  world_R_camera = world_R_camera * Eigen::AngleAxisf(roll_rad, Eigen::Vector3f::UnitZ()).toRotationMatrix();
  Pose world_T_camera;
  world_T_camera.R = world_R_camera;
  world_T_camera.t = position;
  return invert(world_T_camera);
}

Pose randomCamera(const CameraRange& range, std::mt19937& rng) {
  // The same draws in the same order either way, so that datasets made before the distance
  // range existed come out as they did.
  const bool by_distance = range.max_distance_m > 0.f;
  const float drawn = by_distance ? uniform(rng, range.min_distance_m, range.max_distance_m)
                                  : uniform(rng, range.min_height_m, range.max_height_m);
  const float tilt = radians(uniform(rng, 0.f, range.max_tilt_deg));
  const float height = by_distance ? drawn * std::cos(tilt) : drawn;
  const float azimuth = uniform(rng, 0.f, 2.f * kPi);
  const float roll = radians(uniform(rng, -range.max_roll_deg, range.max_roll_deg));
  const Eigen::Vector3f target(uniform(rng, -1.f, 1.f) * range.target_jitter_m,
                               uniform(rng, -1.f, 1.f) * range.target_jitter_m, 0.f);
  return lookDownAt(target, height, tilt, azimuth, roll);
}

std::vector<OrientedBox> binWalls(const PlacementParams& params) {
  const float t = params.bin_wall_thickness_m, h = params.bin_wall_height_m;
  const Eigen::Vector2f in = 0.5f * params.bin_inner_m;
  std::vector<OrientedBox> walls(4);
  for (int k = 0; k < 4; ++k) {
    OrientedBox& w = walls[static_cast<std::size_t>(k)];
    const float sign = k % 2 ? 1.f : -1.f;
    if (k < 2) {  // walls across x, spanning y and the corners
      w.centre = {sign * (in.x() + 0.5f * t), 0.f, 0.5f * h};
      w.half = {0.5f * t, in.y() + t, 0.5f * h};
    } else {
      w.centre = {0.f, sign * (in.y() + 0.5f * t), 0.5f * h};
      w.half = {in.x(), 0.5f * t, 0.5f * h};
    }
  }
  return walls;
}

std::vector<std::optional<Pose>> placeObjects(const std::vector<const Mesh*>& meshes,
                                              std::vector<OrientedBox> obstacles, const PlacementParams& params,
                                              const Camera& camera, const Pose& camera_T_world, std::mt19937& rng) {
  validateCamera(camera);
  const Pose world_T_camera = invert(camera_T_world);
  std::vector<std::optional<Pose>> out;
  for (const Mesh* mesh : meshes) {
    if (!mesh) throw InputError("placeObjects: a mesh is missing");
    std::vector<RestingOrientation> rest = restingOrientations(*mesh);
    if (params.upright_only) {
      std::vector<RestingOrientation> upright;
      for (const auto& r : rest)
        if (r.R(2, 2) > 0.999f) upright.push_back(r);
      if (!upright.empty()) rest = std::move(upright);
    }
    std::optional<Pose> found;
    for (int t = 0; t < params.tries && !found; ++t) {
      std::optional<Pose> p = params.layout == Layout::Table
                                  ? tryOnTable(*mesh, rest, camera, world_T_camera, params, rng)
                                  : tryInBin(*mesh, rest, obstacles, params, rng);
      if (p && clear(orientedBox(*mesh, *p), obstacles, params.gap_m)) found = p;
    }
    if (found) obstacles.push_back(orientedBox(*mesh, *found));
    out.push_back(found);
  }
  return out;
}

Pose supportFrame(const std::vector<const Mesh*>& meshes, const std::vector<Pose>& camera_T_object) {
  if (meshes.size() != camera_T_object.size() || meshes.empty())
    throw InputError("supportFrame: one mesh per pose, at least one");
  Eigen::Vector3f mean_t = Eigen::Vector3f::Zero();
  for (const auto& p : camera_T_object) mean_t += p.t;
  mean_t /= static_cast<float>(camera_T_object.size());
  const Eigen::Vector3f to_camera = -mean_t.normalized();
  // The object axis that agrees across instances (their yaws differ, their up axis does not)
  // and faces the camera; with one instance, the one facing the camera most.
  float best_score = std::numeric_limits<float>::max();
  Eigen::Vector3f up = -Eigen::Vector3f::UnitY();
  for (int axis = 0; axis < 3; ++axis)
    for (const float sign : {-1.f, 1.f}) {
      Eigen::Vector3f sum = Eigen::Vector3f::Zero();
      for (const auto& p : camera_T_object) sum += p.R * (sign * Eigen::Vector3f::Unit(axis));
      const Eigen::Vector3f mean = sum.normalized();
      float spread = 0.f;
      for (const auto& p : camera_T_object)
        spread = std::max(spread, std::acos(std::clamp(mean.dot(p.R.col(axis) * sign), -1.f, 1.f)));
      const float facing = mean.dot(to_camera);
      if (facing <= 0.f) continue;
      const float score = spread + 0.1f * (1.f - facing);
      if (score < best_score) best_score = score, up = mean;
    }
  // Refine the normal to the plane through the instances' lowest points (their contacts with
  // the table): the mean up axis alone tilts by the annotations' few degrees of rotation error.
  for (int iteration = 0; iteration < 3 && meshes.size() >= 2; ++iteration) {
    std::vector<Eigen::Vector3f> contacts;
    for (std::size_t i = 0; i < meshes.size(); ++i) {
      const Pose& p = camera_T_object[i];
      const Eigen::Vector3f local_up = p.R.transpose() * up;
      const auto low = std::min_element(meshes[i]->vertices.begin(), meshes[i]->vertices.end(),
                                        [&](const auto& a, const auto& b) { return a.dot(local_up) < b.dot(local_up); });
      contacts.push_back(p.R * *low + p.t);
    }
    Eigen::Vector3f normal;
    if (contacts.size() == 2) {  // a line on the table: keep up, minus its component along it
      const Eigen::Vector3f d = (contacts[1] - contacts[0]).normalized();
      normal = (up - up.dot(d) * d).normalized();
    } else {
      Eigen::Vector3f mean = Eigen::Vector3f::Zero();
      for (const auto& c : contacts) mean += c;
      mean /= static_cast<float>(contacts.size());
      Eigen::Matrix3f scatter = Eigen::Matrix3f::Zero();
      for (const auto& c : contacts) scatter += (c - mean) * (c - mean).transpose();
      normal = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3f>(scatter).eigenvectors().col(0);
      if (normal.dot(up) < 0.f) normal = -normal;
    }
    if (!normal.allFinite() || normal.dot(up) < std::cos(radians(15.f))) break;  // instances not on one plane
    up = normal;
  }
  // The table touches the lowest instance: none sinks into it.
  float table = std::numeric_limits<float>::max();
  for (std::size_t i = 0; i < meshes.size(); ++i) {
    const Pose& p = camera_T_object[i];
    const Eigen::RowVector3f along = up.transpose() * p.R;
    const float offset = up.dot(p.t);
    for (const auto& v : meshes[i]->vertices) table = std::min(table, along.dot(v.transpose()) + offset);
  }
  // World axes in the camera frame: z up, x the camera's x made horizontal.
  Eigen::Vector3f x = Eigen::Vector3f::UnitX() - up.x() * up;
  if (x.norm() < 1e-3f) x = Eigen::Vector3f::UnitY() - up.y() * up;
  x.normalize();
  Pose camera_T_world;
  camera_T_world.R << x, up.cross(x), up;
  camera_T_world.t = mean_t - (up.dot(mean_t) - table) * up;
  return camera_T_world;
}

}  // namespace vkpose
