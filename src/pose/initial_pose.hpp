#pragma once
// Initial pose (docs/pipeline.md, stage 6; He, Rojas, Guan, section on the initial pose): the rotation
// is the mean of the largest group of mutually close template rotations of a hypothesis, each
// turned onto its own viewing ray; the translation moves the model, rendered at that rotation,
// by the difference between the centroid of the scene points under its mask and the centroid
// of its own rendered points. Rendering is the caller's (MeshRenderer): these functions are
// plain data in, plain data out.
#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "hypotheses/hypotheses.hpp"
#include "geometry/point_cloud.hpp"
#include "render/render.hpp"
#include "vkpose/bank.hpp"
#include "vkpose/config.hpp"
#include "vkpose/geometry.hpp"

namespace vkpose {

/// Axis-angle distance between two rotations, radians in [0, pi].
float rotationDistance(const Eigen::Matrix3f& a, const Eigen::Matrix3f& b);

/// The chordal L2 mean of rotations: the quaternions are sign-aligned with the first (q and -q
/// are one rotation), summed with the weights (empty: equal) and normalized. Close to the
/// geodesic mean for rotations a few degrees apart, which is all it is used for.
Eigen::Matrix3f meanRotation(const std::vector<Eigen::Matrix3f>& rotations, const std::vector<float>& weights = {});

struct RotationGroup {
  Eigen::Matrix3f mean = Eigen::Matrix3f::Identity();
  std::vector<int> members;  ///< indices into the rotations, in input order
  float weight = 0.f;        ///< sum of the members' weights
};

/// Greedy clustering: in input order (callers pass the best templates first), a rotation joins
/// the group whose current mean is nearest, if that is within max_angle_rad, and the group's
/// mean is recomputed; otherwise it starts a group. Measuring against the mean, not the first
/// member, keeps a group from drifting along a chain of near neighbours. Returns the groups
/// largest first (ties: larger weight first).
std::vector<RotationGroup> clusterRotations(const std::vector<Eigen::Matrix3f>& rotations, float max_angle_rad,
                                            const std::vector<float>& weights = {});

/// A rotation group stage 6 starts from: its mean and how many templates voted for it.
struct RotationStart {
  Eigen::Matrix3f R = Eigen::Matrix3f::Identity();  ///< object-to-camera
  int votes = 0;                                     ///< templates in the group
};

struct InitialRotation {
  Eigen::Matrix3f R = Eigen::Matrix3f::Identity();  ///< object-to-camera
  int group_size = 0;  ///< templates in the chosen group
  int candidates = 0;  ///< templates of the hypothesis
  /// InitialPoseParams::second_start_by_fit: the group whose members' stage-4 fit sums
  /// highest, when that is not the largest group (farther than tau_theta from R).
  std::optional<RotationStart> by_fit;
  /// With `starts` > 1: the next largest groups, largest first, up to starts - 1 (by_fit is
  /// left out when it is one of them).
  std::vector<RotationStart> more;
  /// The group of the best-matching template (the first member), when it is neither R nor
  /// one of `more`: without depth no member has a fit to vote by_fit, and in a cluster of
  /// look-alike views the best match can be right where the largest groups are not.
  std::optional<RotationStart> by_best_match;
};

/// Stage 6, rotation: every member's template rotation is turned onto the viewing ray through
/// the object centre it was matched at (off the image centre the same view appears rotated:
/// about 30 degrees at the corners of a 640x480 Kinect image); the rotations are clustered at
/// tau_theta, best similarity first, and the largest group's mean is the initial rotation.
/// The members that stage 4 scored vote again, each by its fit to the scene at `score`'s units
/// (MemberScore::fit), for by_fit. `starts` > 1 also returns the next largest groups (more).
InitialRotation initialRotation(const Hypothesis& h, const TemplateBank& bank, const Camera& camera,
                                const InitialPoseParams& params = {}, const ScoreParams& score = {},
                                int starts = 1);

/// The range of the object's centre on the viewing ray through pixel (x, y), from the range of
/// a template's centre and the depth offset the cluster score measured against the scene
/// (scene minus template depth, mean over the pairs). Depth images hold z, not range: the
/// template's object sits on its camera's optical axis, where the two agree, but on a ray at
/// angle theta to the axis the scene's surface lies at z = range cos(theta). So the template's
/// range plus the offset is the object's z-range, divided by cos(theta): 8 % at 23 degrees
/// off the axis (a cup at 0.91 m placed 7 cm short, where ICP does not reach).
float rangeOnRay(float template_range, float depth_offset, float x, float y, const Camera& camera);

/// A pose with rotation R whose object centre `centre` (object frame) lies on the viewing ray
/// through pixel (x, y), `range` metres from the camera.
Pose poseAtRange(const Eigen::Matrix3f& R, float x, float y, float range, const Eigen::Vector3f& centre,
                 const Camera& camera);

/// A pose with rotation R whose object centre (bank.centre) lies on the viewing ray through the
/// hypothesis centre, at the distance of the hypothesis's best-fitting template plus that
/// member's measured depth offset (converted by rangeOnRay when `range_along_ray`,
/// InitialPoseParams): where stage 6 renders the model.
Pose poseOnViewingRay(const Eigen::Matrix3f& R, const Hypothesis& h, const TemplateBank& bank, const Camera& camera,
                      bool range_along_ray = false);

/// The model surface a rendering of `pose` shows, object frame (metres), row by row: the
/// rendering covers `window` of `camera`'s image (windowCamera).
PointCloud visibleModelPoints(const Rendering& rendering, const Pose& pose, const Camera& camera,
                              const cv::Rect& window);

struct InitialPose {
  Pose pose;  ///< the rendered pose moved by the centroid difference
  /// The model surface the camera sees at the rendered pose, object frame (metres): what ICP
  /// aligns and what verification checks (not all mesh vertices: the hidden back side would
  /// pull the fit towards the camera).
  PointCloud model_points;
  /// Camera-frame scene points around the object (see crop_margin_fraction).
  PointCloud scene_points;
  std::size_t mask_pixels = 0;   ///< rendered object pixels
  std::size_t object_pixels = 0; ///< scene pixels under the mask that fell in the depth band
  /// How far the second try moved the start along the camera's axis, metres (0: the first
  /// start paired); the detector asks more of such a candidate (kSecondTryMinCollision).
  float second_try_m = 0.f;
  bool ok = false;               ///< false: too few object pixels; `why` says so
  std::string why;
};

/// The image window stage 6 renders a candidate in: the box of the object's bounding sphere
/// (centre `centre` in the object frame, `radius` metres) projected at `pose`, grown by
/// `margin_px`, within the image. Empty when the sphere is behind the camera or off the image.
/// A window instead of the whole frame: a 640x480 rendering per candidate (depth, normals,
/// colour: 17 MB) cost 20-60 ms on lavapipe; the object covers a few percent of it.
cv::Rect projectedWindow(const Pose& pose, const Eigen::Vector3f& centre, float radius, const Camera& camera,
                         int margin_px = 4);

/// The camera that renders `window` of `camera`'s image: the same rays, the principal point
/// moved to the window's corner, the window's size.
Camera windowCamera(const Camera& camera, const cv::Rect& window);

/// Stage 6, translation. `rendering` is the model rendered at `rendered` with the scene's
/// camera, either the whole image or the part of it `window` says (windowCamera; an empty
/// window means the whole image); `scene_depth_m` is the scene depth in metres (0 = none). The
/// scene points under the mask that lie in the depth band and the rendered points at the same
/// pixels and at the pixels where the scene is farther (the mask overhangs the object: that
/// is the misplacement to correct) give the two centroids. Pixels where the scene is nearer
/// (occluded) or has no depth are left out of both, so occlusion does not bias the shift.
InitialPose initialTranslation(const Rendering& rendering, const Pose& rendered, const cv::Mat& scene_depth_m,
                               const Camera& camera, float diameter, const InitialPoseParams& params = {},
                               const cv::Rect& window = {});

}  // namespace vkpose
