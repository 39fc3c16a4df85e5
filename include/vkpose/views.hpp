#pragma once
// Training viewpoints (DESIGN.md stage 0): camera positions spread uniformly on a sphere
// around the object, at several distances, each with several in-plane rotations.
#include <string>
#include <vector>

#include <Eigen/Core>

namespace vkpose {

/// An evenly stepped range, both ends included: from, from + step, ..., to.
struct SteppedRange {
  float from = 0.f, to = 0.f, step = 1.f;
  std::vector<float> values() const;
};

/// Parses "A:B:STEP" (or a single value "A"); throws InputError on nonsense.
SteppedRange parseSteppedRange(const std::string& text, const std::string& what);

struct ViewSamplingParams {
  /// Viewpoints on the (hemi)sphere, spread by a Fibonacci lattice. Paper: 216.
  int viewpoints = 216;
  /// Upper hemisphere (object +z up, cameras above the object's centre) or the full sphere.
  bool full_sphere = false;
  /// Camera distances from the object's centre, metres. Paper: 0.6 to 1.0 m, 0.1 m apart.
  SteppedRange radii{0.6f, 1.0f, 0.1f};
  /// In-plane rotations about the optical axis, degrees. Paper: -60 to +60, 10 apart.
  SteppedRange inplane_deg{-60.f, 60.f, 10.f};
};

/// Throws InputError when the counts or ranges are out of bounds.
void validateViewSampling(const ViewSamplingParams& params);

/// One training view: the object-to-camera pose (x_cam = R x_obj + t) that puts `centre`
/// (in object coordinates) on the optical axis at `distance`.
struct TrainingView {
  Eigen::Matrix3f R = Eigen::Matrix3f::Identity();
  Eigen::Vector3f t = Eigen::Vector3f::Zero();
  float distance = 0.f;     ///< metres from the camera to the object's centre
  float inplane_deg = 0.f;  ///< in-plane rotation of this view
  int viewpoint = 0;        ///< index of the viewpoint on the sphere
};

/// Unit directions from the object's centre to the cameras: a Fibonacci lattice over the
/// upper hemisphere (z >= 0) or the whole sphere.
std::vector<Eigen::Vector3f> sphereViewpoints(int count, bool full_sphere);

/// A camera at `centre + distance * direction` looking at `centre`, image "up" along the
/// object's +z where possible (+y at the poles), then rotated in-plane by `inplane_deg`.
TrainingView lookAtView(const Eigen::Vector3f& direction, const Eigen::Vector3f& centre, float distance,
                        float inplane_deg);

/// All views, viewpoint-major, then radius, then in-plane rotation.
std::vector<TrainingView> sampleViews(const ViewSamplingParams& params, const Eigen::Vector3f& centre);

/// The views whose camera sits within `max_polar_deg` of the object's +z axis, seen from
/// `centre`: for objects that only ever stand upright under a camera looking down, the rest
/// of the hemisphere is templates that can only match wrongly.
std::vector<TrainingView> viewsAbove(const std::vector<TrainingView>& views, const Eigen::Vector3f& centre,
                                     float max_polar_deg);

}  // namespace vkpose
