#pragma once
// Physically plausible placements for synthetic scenes: objects resting on a table in a stable
// orientation, or dropped into a bin until they settle, never interpenetrating; a camera looking
// down at them from a working height; and the table under poses that come from a file. World
// frame: the table top is z = 0, +z up, metres.
//
// Random numbers come from std::mt19937 through uniform() below, not from the standard
// distributions, whose output the standard leaves to each library: the same seed gives the same
// scene with any compiler.
#include <optional>
#include <random>
#include <vector>

#include "render/render.hpp"
#include "vkpose/geometry.hpp"
#include "vkpose/synth.hpp"

namespace vkpose {

/// A uniform number in [lo, hi) from 24 bits of the generator.
inline float uniform(std::mt19937& rng, float lo, float hi) {
  return lo + (hi - lo) * static_cast<float>(rng() >> 8) * (1.f / 16777216.f);
}


/// An oriented box, world frame: centre, axes (columns, unit) and half side lengths, metres.
struct OrientedBox {
  Eigen::Vector3f centre = Eigen::Vector3f::Zero();
  Eigen::Matrix3f axes = Eigen::Matrix3f::Identity();
  Eigen::Vector3f half = Eigen::Vector3f::Zero();
};

/// The mesh's bounding box carried by `world_T_object`: it holds every vertex, so boxes that
/// do not intersect are objects that do not intersect.
OrientedBox orientedBox(const Mesh& mesh, const Pose& world_T_object);

/// Separating-axis test over the 15 axes of two boxes; boxes closer than `gap_m` on every
/// axis count as intersecting.
bool boxesIntersect(const OrientedBox& a, const OrientedBox& b, float gap_m = 0.f);

/// A way the object rests on a table: one of the six axis directions down, where training's
/// resting test says the object stands on it (findUpAxis, RestingCandidate::stands).
struct RestingOrientation {
  Eigen::Matrix3f R = Eigen::Matrix3f::Identity();  ///< object-to-world rotation, no yaw
  float lift_m = 0.f;  ///< translation along z that puts its lowest point on the table
  float weight = 0.f;  ///< relative chance: 1 / centroid height (low and stable is likely)
};

/// The stable resting orientations among the six axis directions down: the ones a bank
/// trained with --resting all covers (all six, weight 1, for a mesh that stands on none).
std::vector<RestingOrientation> restingOrientations(const Mesh& mesh);

/// camera_T_world of a camera `height_m` above the table whose optical axis passes through
/// `target` (on the table), tilted `tilt_rad` from the vertical, standing on the side of
/// azimuth `azimuth_rad`, rolled `roll_rad` about its axis. Image up points away from it.
Pose lookDownAt(const Eigen::Vector3f& target, float height_m, float tilt_rad, float azimuth_rad, float roll_rad);

/// A camera drawn from `range` looking at the origin (jittered).
Pose randomCamera(const CameraRange& range, std::mt19937& rng);

/// The bin's four walls on the table, centred at the origin, as boxes (world frame).
std::vector<OrientedBox> binWalls(const PlacementParams& params);

/// Places the meshes in order, each clear of `obstacles` and of those placed before it:
/// table: a stable resting orientation with a random yaw at a point of the table the camera
/// sees (camera_T_world, camera) away from the image border; bin: a resting orientation with
/// a random yaw and tip at a random point over the bin, lowered to the lowest free height. Returns world_T_object per
/// mesh; nothing for a mesh that found no free place in params.tries.
std::vector<std::optional<Pose>> placeObjects(const std::vector<const Mesh*>& meshes,
                                              std::vector<OrientedBox> obstacles, const PlacementParams& params,
                                              const Camera& camera, const Pose& camera_T_world, std::mt19937& rng);

/// The table under objects whose camera poses are given (Tejani et al.'s scenes: instances
/// standing on one table): the table normal is the object axis (+-x, +-y, +-z) that points the
/// same way in every instance and towards the camera, the table touches the lowest instance.
/// Returns camera_T_world with the origin under the instances' mean position.
Pose supportFrame(const std::vector<const Mesh*>& meshes, const std::vector<Pose>& camera_T_object);

}  // namespace vkpose
