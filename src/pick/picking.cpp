// Grasps placed at detections, the gripper swept in and out along its approach and tested
// against the bin (sampled on the gripper's surface against the bin's slabs) and against
// points (the other detections' surfaces, the scene's depth points that are not the part
// itself), then the pick list. docs/picking.md has the frames and the ranking.
#include <algorithm>
#include <cmath>
#include <map>
#include <numbers>
#include <optional>
#include <utility>

#include <fmt/format.h>

#include "geometry/nearest_neighbours.hpp"
#include "vkpose/error.hpp"
#include "vkpose/picking.hpp"

namespace vkpose {
namespace {

float degrees(float rad) { return rad * 180.f / std::numbers::pi_v<float>; }

Eigen::Matrix3f axisAngle(const Eigen::Vector3f& axis, float rad) {
  return Eigen::AngleAxisf(rad, axis.normalized()).toRotationMatrix();
}

/// The swept gripper in its own frame: z from -(length + the farther of approach and retreat)
/// to 0, the envelope's cross-section about z.
struct SweptGripper {
  GripperShape shape;
  float z_min = 0.f;
  float sweep = 0.f;
  float palm_z_max = 0.f;  ///< the palm's near end: 0 without fingers, else -finger_length
  float finger_x = 0.f;    ///< the fingers' centres at +-finger_x

  explicit SweptGripper(const Grasp& g)
      : shape(g.gripper),
        z_min(-(g.gripper.length + std::max(g.approach_m, g.retreat_m))),
        sweep(std::max(g.approach_m, g.retreat_m)),
        palm_z_max(g.opening_m > 0.f ? -g.gripper.finger_length : 0.f),
        finger_x(0.5f * (g.opening_m + g.gripper.finger_thickness)) {}
  bool fingers() const { return palm_z_max < 0.f; }

  /// Distance from a gripper-frame point to the envelope (0 inside): the palm's cross-section
  /// from z_min to palm_z_max, and the two fingers from -(finger_length + sweep) to 0.
  float distance(const Eigen::Vector3f& p) const {
    auto span = [](float v, float lo, float hi) { return std::max({0.f, v - hi, lo - v}); };
    float dr = 0.f;
    if (shape.kind == GripperShape::Kind::Cylinder) {
      dr = std::max(0.f, std::hypot(p.x(), p.y()) - shape.radius);
    } else {
      dr = std::hypot(std::max(0.f, std::abs(p.x()) - shape.size_x / 2), std::max(0.f, std::abs(p.y()) - shape.size_y / 2));
    }
    float d = std::hypot(dr, span(p.z(), z_min, palm_z_max));
    if (fingers()) {
      const float dz = span(p.z(), palm_z_max - sweep, 0.f), dy = span(p.y(), -shape.finger_width / 2, shape.finger_width / 2);
      for (const float cx : {-finger_x, finger_x}) {
        const float dx = span(p.x(), cx - shape.finger_thickness / 2, cx + shape.finger_thickness / 2);
        d = std::min(d, std::sqrt(dx * dx + dy * dy + dz * dz));
      }
    }
    return d;
  }
  float halfWidth() const {
    const float palm =
        shape.kind == GripperShape::Kind::Cylinder ? shape.radius : 0.5f * std::hypot(shape.size_x, shape.size_y);
    return fingers() ? std::max(palm, std::hypot(finger_x + shape.finger_thickness / 2, shape.finger_width / 2)) : palm;
  }
  /// A bounding sphere in the gripper frame: centre on the axis, radius.
  std::pair<Eigen::Vector3f, float> sphere() const {
    const float h = -z_min / 2;
    return {Eigen::Vector3f(0, 0, -h), std::hypot(h, halfWidth())};
  }
  /// Points on the envelope's surface and axis, at most `spacing` apart.
  std::vector<Eigen::Vector3f> samples(float spacing) const {
    std::vector<Eigen::Vector3f> out;
    const float z_max = palm_z_max;
    const int nz = std::max(2, static_cast<int>(std::ceil((z_max - z_min) / spacing)) + 1);
    if (fingers()) {
      const float z0 = palm_z_max - sweep;
      const int fz = std::max(2, static_cast<int>(std::ceil(-z0 / spacing)) + 1);
      const int fy = std::max(2, static_cast<int>(std::ceil(shape.finger_width / spacing)) + 1);
      for (const float cx : {-finger_x, finger_x})
        for (int iz = 0; iz < fz; ++iz)
          for (int iy = 0; iy < fy; ++iy)
            for (const float sx : {-0.5f, 0.5f})
              out.emplace_back(cx + sx * shape.finger_thickness,
                               shape.finger_width * (static_cast<float>(iy) / static_cast<float>(fy - 1) - 0.5f),
                               z0 * (1.f - static_cast<float>(iz) / static_cast<float>(fz - 1)));
    }
    for (int iz = 0; iz < nz; ++iz) {
      const float z = z_min + (z_max - z_min) * static_cast<float>(iz) / static_cast<float>(nz - 1);
      out.emplace_back(0.f, 0.f, z);
      if (shape.kind == GripperShape::Kind::Cylinder) {
        const int n = std::max(8, static_cast<int>(std::ceil(2 * std::numbers::pi_v<float> * shape.radius / spacing)));
        for (int k = 0; k < n; ++k) {
          const float a = 2 * std::numbers::pi_v<float> * static_cast<float>(k) / static_cast<float>(n);
          out.emplace_back(shape.radius * std::cos(a), shape.radius * std::sin(a), z);
        }
      } else {
        const int nx = std::max(2, static_cast<int>(std::ceil(shape.size_x / spacing)) + 1);
        const int ny = std::max(2, static_cast<int>(std::ceil(shape.size_y / spacing)) + 1);
        for (int i = 0; i < nx; ++i)
          for (int j = 0; j < ny; ++j)
            if (i == 0 || j == 0 || i == nx - 1 || j == ny - 1)
              out.emplace_back(shape.size_x * (static_cast<float>(i) / static_cast<float>(nx - 1) - 0.5f),
                               shape.size_y * (static_cast<float>(j) / static_cast<float>(ny - 1) - 0.5f), z);
      }
    }
    return out;
  }
};

/// Which part of the bin a bin-frame point lies in ("" for none): the floor slab under the
/// inside and the walls, each as thick as the wall.
std::string binPart(const BinBox& bin, const Eigen::Vector3f& p) {
  const float hx = bin.inner.x() / 2, hy = bin.inner.y() / 2, h = bin.inner.z(), t = bin.wall_thickness_m;
  const bool within_outer = std::abs(p.x()) <= hx + t && std::abs(p.y()) <= hy + t;
  if (!within_outer || p.z() > h) return {};
  if (p.z() < 0.f) return p.z() >= -t ? "floor" : std::string();
  if (p.x() > hx) return "wall (+x)";
  if (p.x() < -hx) return "wall (-x)";
  if (p.y() > hy) return "wall (+y)";
  if (p.y() < -hy) return "wall (-y)";
  return {};
}

std::string binCollision(const SweptGripper& swept, const Pose& camera_T_gripper, const BinBox& bin) {
  const Pose bin_T_gripper = compose(invert(bin.pose), camera_T_gripper);
  const float spacing = std::clamp(bin.wall_thickness_m * 0.7f, 0.002f, 0.008f);
  for (const Eigen::Vector3f& s : swept.samples(spacing)) {
    const std::string part = binPart(bin, bin_T_gripper.R * s + bin_T_gripper.t);
    if (!part.empty()) return "hits the bin's " + part;
  }
  return {};
}

/// The gripper-frame point of a camera-frame point.
Eigen::Vector3f inGripper(const Pose& gripper_T_camera, const Eigen::Vector3f& p) {
  return gripper_T_camera.R * p + gripper_T_camera.t;
}

/// Points on a mesh's surface at most about `spacing` apart (area-weighted, deterministic),
/// with their faces' normals; object frame.
void surfacePoints(const Mesh& mesh, float spacing, std::vector<Eigen::Vector3f>& points,
                   std::vector<Eigen::Vector3f>& normals) {
  for (const Eigen::Vector3i& f : mesh.faces) {
    const Eigen::Vector3f a = mesh.vertices[static_cast<std::size_t>(f.x())];
    const Eigen::Vector3f b = mesh.vertices[static_cast<std::size_t>(f.y())];
    const Eigen::Vector3f c = mesh.vertices[static_cast<std::size_t>(f.z())];
    const Eigen::Vector3f cross = (b - a).cross(c - a);
    const float area = 0.5f * cross.norm();
    if (!(area > 0.f)) continue;
    const Eigen::Vector3f n = cross.normalized();
    // A triangular grid of k rows: about area / (spacing^2 / 2) points.
    const int k = std::max(1, static_cast<int>(std::ceil(std::sqrt(2.f * area) / spacing)));
    for (int i = 0; i < k; ++i)
      for (int j = 0; i + j < k; ++j) {
        const float u = (static_cast<float>(i) + 1.f / 3) / static_cast<float>(k);
        const float v = (static_cast<float>(j) + 1.f / 3) / static_cast<float>(k);
        points.push_back(a + u * (b - a) + v * (c - a));
        normals.push_back(n);
      }
  }
}

/// A detection's surface in the camera frame.
struct PlacedPart {
  std::vector<Eigen::Vector3f> points, normals;
  Eigen::Vector3f centre = Eigen::Vector3f::Zero();
  float radius = 0.f;
};

PlacedPart placePart(const Detection& d, const TemplateBank& bank, float spacing) {
  PlacedPart part;
  std::vector<Eigen::Vector3f> points, normals;
  surfacePoints(bank.mesh, spacing, points, normals);
  for (std::size_t i = 0; i < points.size(); ++i) {
    part.points.push_back(d.pose.R * points[i] + d.pose.t);
    part.normals.push_back(d.pose.R * normals[i]);
  }
  part.centre = d.pose.R * bank.centre + d.pose.t;
  part.radius = 0.f;
  for (const auto& p : part.points) part.radius = std::max(part.radius, (p - part.centre).norm());
  return part;
}

/// Share of a part's camera-facing surface that the scene does not hide (its own nearest
/// surface per pixel, compared with the scene's depth; pixels without depth left out).
float visibleShare(const PlacedPart& part, const cv::Mat& depth_m, const Camera& camera, float tolerance) {
  std::vector<std::pair<long, float>> nearest;  // (pixel, depth) of the part's own front
  for (std::size_t i = 0; i < part.points.size(); ++i) {
    const Eigen::Vector3f& p = part.points[i];
    if (p.z() <= 0.f || part.normals[i].dot(p) >= 0.f) continue;
    const Eigen::Vector2f px = camera.project(p);
    const int u = static_cast<int>(std::lround(px.x())), v = static_cast<int>(std::lround(px.y()));
    if (u < 0 || v < 0 || u >= depth_m.cols || v >= depth_m.rows) continue;
    nearest.emplace_back(static_cast<long>(v) * depth_m.cols + u, p.z());
  }
  std::sort(nearest.begin(), nearest.end());
  int seen = 0, hidden = 0;
  for (std::size_t i = 0; i < nearest.size(); ++i) {
    if (i > 0 && nearest[i].first == nearest[i - 1].first) continue;  // the nearest sample of each pixel
    const float scene = depth_m.at<float>(static_cast<int>(nearest[i].first / depth_m.cols),
                                          static_cast<int>(nearest[i].first % depth_m.cols));
    if (!(scene > 0.f)) continue;
    (scene < nearest[i].second - tolerance ? hidden : seen) += 1;
  }
  return seen + hidden > 0 ? static_cast<float>(seen) / static_cast<float>(seen + hidden) : 0.f;
}

/// The scene's depth points near the swept gripper that are not the part itself: how many lie
/// inside it, and the nearest one's distance to it.
struct SceneClearance {
  int inside = 0;
  float nearest_m = 0.f;
};

SceneClearance sceneClearance(const SweptGripper& swept, const Pose& camera_T_gripper, const cv::Mat& depth_m,
                              const Camera& camera, const NearestNeighbours& own, float part_tolerance, float clearance) {
  SceneClearance out{0, clearance};
  if (depth_m.empty()) return out;
  const Pose gripper_T_camera = invert(camera_T_gripper);
  // The image window of the swept gripper's bounding sphere, grown by the clearance.
  const auto [centre_g, radius] = swept.sphere();
  const Eigen::Vector3f c = camera_T_gripper.R * centre_g + camera_T_gripper.t;
  const float r = radius + clearance;
  if (c.z() - r <= 0.01f) return out;  // reaches the camera: the window would be the whole image
  const Eigen::Vector2f px = camera.project(c);
  const float pr = camera.pixelsAcross(r, c.z() - r);
  const int u0 = std::max(0, static_cast<int>(px.x() - pr)), u1 = std::min(depth_m.cols - 1, static_cast<int>(px.x() + pr));
  const int v0 = std::max(0, static_cast<int>(px.y() - pr)), v1 = std::min(depth_m.rows - 1, static_cast<int>(px.y() + pr));
  for (int v = v0; v <= v1; v += 2)
    for (int u = u0; u <= u1; u += 2) {
      const float z = depth_m.at<float>(v, u);
      if (!(z > 0.f)) continue;
      const Eigen::Vector3f p = camera.backProject(static_cast<float>(u), static_cast<float>(v), z);
      const float d = swept.distance(inGripper(gripper_T_camera, p));
      if (d >= out.nearest_m && d > 0.f) continue;
      float own_sqr = 0.f;
      if (own.nearest(p, own_sqr) >= 0 && own_sqr <= part_tolerance * part_tolerance) continue;  // the part itself
      if (d == 0.f) ++out.inside;
      out.nearest_m = std::min(out.nearest_m, d);
    }
  return out;
}

/// The first of `obstacles` with a point within `margin` of the swept gripper (inside it at
/// 0), and the nearest point's distance to it (up to `clearance`).
std::pair<int, float> pointCollision(const SweptGripper& swept, const Pose& camera_T_gripper,
                                     const std::vector<const std::vector<Eigen::Vector3f>*>& obstacles, float clearance,
                                     float margin = 0.f) {
  const Pose gripper_T_camera = invert(camera_T_gripper);
  const auto [centre_g, radius] = swept.sphere();
  const Eigen::Vector3f c = camera_T_gripper.R * centre_g + camera_T_gripper.t;
  float nearest = clearance;
  for (std::size_t k = 0; k < obstacles.size(); ++k)
    for (const Eigen::Vector3f& p : *obstacles[k]) {
      if ((p - c).squaredNorm() > (radius + clearance) * (radius + clearance)) continue;
      const float d = swept.distance(inGripper(gripper_T_camera, p));
      if (d <= margin) return {static_cast<int>(k), d};
      nearest = std::min(nearest, d);
    }
  return {-1, nearest};
}

PlacedGrasp placeGrasp(const Grasp& g, const Pose& object_pose, const Eigen::Vector3f& axis) {
  PlacedGrasp p;
  p.name = g.name;
  p.priority = g.priority;
  p.pose = compose(object_pose, g.pose);
  const Eigen::Vector3f z = p.pose.R.col(2);
  p.approach_point = p.pose.t - g.approach_m * z;
  p.retreat_point = p.pose.t - g.retreat_m * z;
  p.tilt_deg = degrees(std::acos(std::clamp(z.dot(axis.normalized()), -1.f, 1.f)));
  p.opening_m = g.opening_m;
  p.suction_radius_m = g.suction_radius_m;
  p.source = g;
  return p;
}

/// Why a detection is not picked at all, whatever its grasps: its outline strays from the
/// image's edges, or its colour disagrees with its model's; "" when neither.
std::string poseTooUncertainToPick(const Detection& d, const PickParams& params) {
  const bool colour_gate = params.min_colour_agreement > 0.f;
  const bool colour_passed = colour_gate && d.colour_measured && d.colour_agreement >= params.min_colour_agreement;
  // The allowance's share: none at kColourOutlineAllowanceFrom, all of it at an agreement of 1.
  const float share =
      std::clamp((d.colour_agreement - kColourOutlineAllowanceFrom) / (1.f - kColourOutlineAllowanceFrom), 0.f, 1.f);
  const float min_outline = params.min_outline_on_edges - (colour_passed ? share * params.colour_outline_allowance : 0.f);
  if (params.min_outline_on_edges > 0.f && d.outline_on_edges < min_outline)  // false for NaN: not measured
    return fmt::format("the pose's outline lies on the image's edges for {:.1f} % of it (a pick needs {:.0f} %{}): too "
                       "uncertain a pose to grip, or something else of its size",
                       100.f * d.outline_on_edges, 100.f * min_outline, colour_passed ? ", its colour having passed" : "");
  if (colour_gate && d.colour_agreement < params.min_colour_agreement)
    return fmt::format("its colour agrees with the model's {:.2f} (a pick needs {:.2f}): something else of its shape",
                       d.colour_agreement, params.min_colour_agreement);
  return {};
}

/// The combined rank's weights of a grasp's reach and free space (docs/picking.md).
constexpr float kReachWeight = 0.15f, kFreeSpaceWeight = 0.1f;

float reachOf(const PlacedGrasp& g, const PickParams& params) {
  return std::clamp(1.f - g.tilt_deg / params.max_tilt_deg, 0.f, 1.f);
}

float freeSpaceOf(const PlacedGrasp& g, const PickParams& params) {
  return params.clearance_m > 0.f ? std::clamp(g.clearance_m / params.clearance_m, 0.f, 1.f) : 1.f;
}

/// What the combined rank gives a grasp's approach: its reach and free-space terms.
float approachValue(const PlacedGrasp& g, const PickParams& params) {
  return kReachWeight * reachOf(g, params) + kFreeSpaceWeight * freeSpaceOf(g, params);
}

float rankOf(const Pick& p, PickOrder order) {
  switch (order) {
    case PickOrder::Height: return p.height;
    case PickOrder::Score: return p.score;
    case PickOrder::Visible: return p.visible;
    case PickOrder::Combined: break;
  }
  return 0.3f * p.score + 0.25f * p.height + 0.2f * p.visible + kReachWeight * p.reach + kFreeSpaceWeight * p.free;
}
}  // namespace

std::vector<Grasp> expandBySymmetry(const std::vector<Grasp>& grasps, const TemplateBank& bank, int steps) {
  std::vector<Pose> turns = {Pose{}};
  // Continuous about the axis of revolution: the up axis of a bank trained --symmetric, through
  // a near-symmetry's point on that axis when the bank found one (the true axis), else through
  // the bank's centre; or the axis of a body of revolution that no flag declared (a lidded cup
  // passes the turns of both a hexagon and a square about its axis).
  std::optional<std::pair<Eigen::Vector3f, Eigen::Vector3f>> axis;  // direction, point
  if (bank.symmetric) {
    const Eigen::Vector3f up = bank.params.views.up.normalized();
    Eigen::Vector3f point = bank.centre;
    for (const NearSymmetry& s : bank.near_symmetries)
      if (std::abs(s.axis.normalized().dot(up)) > 0.99f) point = s.point;
    axis = {up, point};
  }
  const std::optional<NearSymmetry> revolution =
      bank.symmetric ? std::nullopt : revolutionAxis(bank.near_symmetries);
  if (revolution) axis = {revolution->axis.normalized(), revolution->point};
  if (axis)
    for (int k = 1; k < std::max(1, steps); ++k) {
      const Eigen::Matrix3f R =
          axisAngle(axis->first, 2 * std::numbers::pi_v<float> * static_cast<float>(k) / static_cast<float>(steps));
      turns.push_back({R, axis->second - R * axis->second});
    }
  for (const NearSymmetry& s : bank.near_symmetries)
    if (!revolution || std::abs(s.axis.normalized().dot(revolution->axis.normalized())) < 0.9999f)
      turns.push_back(s.transform());  // the turns about the axis of revolution are copies above
  std::vector<Grasp> out;
  for (const Grasp& g : grasps)
    for (const Pose& turn : turns) {
      Grasp copy = g;
      copy.pose = compose(turn, g.pose);
      out.push_back(copy);
    }
  return out;
}

std::string gripperCollision(const Grasp& grasp, const Pose& camera_T_gripper, const std::optional<BinBox>& bin,
                             const std::vector<std::vector<Eigen::Vector3f>>& obstacles,
                             const std::vector<std::string>& names) {
  const SweptGripper swept(grasp);
  if (bin) {
    const std::string why = binCollision(swept, camera_T_gripper, *bin);
    if (!why.empty()) return why;
  }
  std::vector<const std::vector<Eigen::Vector3f>*> sets;
  for (const auto& o : obstacles) sets.push_back(&o);
  const auto [hit, nearest] = pointCollision(swept, camera_T_gripper, sets, 0.f);
  (void)nearest;
  if (hit < 0) return {};
  return "hits " + (static_cast<std::size_t>(hit) < names.size() ? names[static_cast<std::size_t>(hit)]
                                                                  : fmt::format("obstacle {}", hit));
}

namespace {

/// What a placed grasp meets: the other detections' surfaces (and their indices), the part's
/// own surface, the depth image, the bin.
struct GraspSurroundings {
  const std::vector<Detection>& detections;
  const std::vector<const std::vector<Eigen::Vector3f>*>& others;
  const std::vector<std::size_t>& other_index;
  const NearestNeighbours& own;
  const cv::Mat& depth_m;
  const Camera& camera;
  const std::optional<BinBox>& bin;
  const PickParams& params;
};

/// Why the grasp `p` (placed from `g`) is refused: too tilted, hitting the bin, another
/// detection or scene points; "" when it is valid, with its clearance set.
std::string refusal(PlacedGrasp& p, const Grasp& g, const GraspSurroundings& at) {
  const PickParams& params = at.params;
  if (p.tilt_deg > params.max_tilt_deg)
    return fmt::format("approach tilted {:.0f} degrees from the approach axis (at most {:.0f})", p.tilt_deg,
                       params.max_tilt_deg);
  const SweptGripper swept(g);
  if (at.bin) {
    std::string why = binCollision(swept, p.pose, *at.bin);
    if (!why.empty()) return why;
  }
  const auto [hit, nearest] = pointCollision(swept, p.pose, at.others, params.clearance_m, params.neighbour_margin_m);
  if (hit >= 0) {
    const std::size_t other = at.other_index[static_cast<std::size_t>(hit)];
    // Numbered from 1, as the detection table and the overlay label them.
    return fmt::format("hits detection {} ({})", other + 1, at.detections[other].object);
  }
  const SceneClearance scene =
      sceneClearance(swept, p.pose, at.depth_m, at.camera, at.own, params.part_tolerance_m, params.clearance_m);
  p.clearance_m = std::min(nearest, scene.nearest_m);
  if (scene.inside >= params.min_blocking_points)
    return fmt::format("{} scene points in the gripper's way (something lies on or beside the part)", scene.inside);
  return {};
}

}  // namespace

Eigen::Vector3f approachAxis(const PickParams& params, const std::optional<BinBox>& bin) {
  if (params.approach_axis) {
    if (!(params.approach_axis->norm() > 0.f) || !params.approach_axis->allFinite())
      throw InputError("the approach axis must be a finite direction, not zero");
    return params.approach_axis->normalized();
  }
  if (bin) return -bin->pose.R.col(2).normalized();  // the bin's z is up, out of it
  return Eigen::Vector3f::UnitZ();
}

PickPlan planPicks(const std::vector<Detection>& detections, const std::vector<TemplateBank>& banks,
                   const std::vector<std::vector<Grasp>>& grasps, const cv::Mat& depth_m, const Camera& camera,
                   const std::optional<BinBox>& bin, const PickParams& params) {
  if (!depth_m.empty() && depth_m.type() != CV_32F) throw InputError("planPicks: the depth must be metres (CV_32F)");
  if (!(params.max_tilt_deg > 0.f && params.max_tilt_deg <= 180.f))
    throw InputError(fmt::format("the largest approach tilt must be in (0, 180] degrees, not {}", params.max_tilt_deg));
  const Eigen::Vector3f approach_axis = approachAxis(params, bin);
  PickPlan plan;
  plan.detections.resize(detections.size());
  // Each detection's surface, about 3 mm apart (small parts 1/30 of their size).
  std::vector<PlacedPart> parts;
  for (const Detection& d : detections) {
    const TemplateBank& bank = banks.at(static_cast<std::size_t>(d.bank));
    parts.push_back(placePart(d, bank, std::clamp(bank.diameter / 30.f, 0.001f, 0.003f)));
  }
  float z_near = 1e9f, z_far = 0.f;
  for (const PlacedPart& p : parts) z_near = std::min(z_near, p.centre.z()), z_far = std::max(z_far, p.centre.z());

  // Why each detection is too uncertain to pick ("" when it is not): it is then neither picked
  // nor an obstacle to another's grasp.
  std::vector<std::string> uncertain;
  for (const Detection& d : detections) uncertain.push_back(poseTooUncertainToPick(d, params));

  for (std::size_t i = 0; i < detections.size(); ++i) {
    const Detection& d = detections[i];
    const auto b = static_cast<std::size_t>(d.bank);
    if (b >= grasps.size() || grasps[b].empty()) continue;
    if (const std::string& why = uncertain[i]; !why.empty()) {
      std::vector<std::string> names;
      for (const Grasp& g : grasps[b])
        if (std::find(names.begin(), names.end(), g.name) == names.end()) names.push_back(g.name);
      for (const std::string& name : names) plan.detections[i].refused.push_back({name, why});
      continue;
    }
    const NearestNeighbours own(parts[i].points, 0.005f);
    // The other detections a gripper must miss: those sure enough to be picked themselves. A
    // pose too uncertain to grip is as uncertain an obstacle (most often a look-alike on a
    // box beside the part, which blocked the part's side grasp); what the scene shows of it
    // is still in the scene's points, which the gripper must miss too.
    std::vector<const std::vector<Eigen::Vector3f>*> others;
    std::vector<std::size_t> other_index;
    for (std::size_t j = 0; j < parts.size(); ++j)
      if (j != i && uncertain[j].empty())
        others.push_back(&parts[j].points), other_index.push_back(j);

    // Copies of each named grasp, least tilted first (the valid one chosen below).
    std::map<std::string, std::vector<PlacedGrasp>> copies;
    std::map<std::string, std::vector<const Grasp*>> sources;
    std::vector<std::string> order;
    for (const Grasp& g : grasps[b]) {
      if (!copies.count(g.name)) order.push_back(g.name);
      copies[g.name].push_back(placeGrasp(g, d.pose, approach_axis));
      sources[g.name].push_back(&g);
    }
    DetectionGrasps& out = plan.detections[i];
    for (const std::string& name : order) {
      std::vector<std::size_t> idx(copies[name].size());
      for (std::size_t k = 0; k < idx.size(); ++k) idx[k] = k;
      std::stable_sort(idx.begin(), idx.end(),
                       [&](std::size_t x, std::size_t y) { return copies[name][x].tilt_deg < copies[name][y].tilt_deg; });
      // Of the copies that hit nothing, the one whose approach the combined rank values most
      // (reach and free space): a copy that grazes a neighbour gives way to one a few degrees
      // more tilted with room around it, since poses and depth are millimetres off and the
      // neighbour's far side is not seen. Copies come least tilted first, so one with the full
      // clearance cannot be beaten by a later one.
      std::optional<PlacedGrasp> best;
      float best_value = -1.f;
      std::string first_reason;
      for (const std::size_t k : idx) {
        PlacedGrasp p = copies[name][k];
        const std::string why = refusal(p, *sources[name][k], {detections, others, other_index, own, depth_m, camera, bin, params});
        if (!why.empty()) {
          if (first_reason.empty()) first_reason = why;
          if (p.tilt_deg > params.max_tilt_deg) break;  // and so is every copy after it
          continue;
        }
        if (const float value = approachValue(p, params); value > best_value) best = p, best_value = value;
        if (p.clearance_m >= params.clearance_m) break;
      }
      if (best) out.valid.push_back(*best);
      else out.refused.push_back({name, first_reason});
    }
    std::stable_sort(out.valid.begin(), out.valid.end(), [](const PlacedGrasp& x, const PlacedGrasp& y) {
      return x.priority != y.priority ? x.priority > y.priority : x.tilt_deg < y.tilt_deg;
    });
    if (out.valid.empty()) continue;

    Pick pick;
    pick.detection = static_cast<int>(i);
    pick.grasp = out.valid.front();
    pick.score = std::clamp(d.score, 0.f, 1.f);
    pick.visible = depth_m.empty() ? 1.f : visibleShare(parts[i], depth_m, camera, 0.01f);
    if (bin) {
      const Eigen::Vector3f in_bin = invert(bin->pose).R * parts[i].centre + invert(bin->pose).t;
      pick.height = std::clamp(in_bin.z() / bin->inner.z(), 0.f, 1.f);
    } else {
      pick.height = z_far > z_near ? (z_far - parts[i].centre.z()) / (z_far - z_near) : 1.f;
    }
    pick.reach = reachOf(pick.grasp, params);
    pick.free = freeSpaceOf(pick.grasp, params);
    pick.rank = rankOf(pick, params.order);
    plan.picks.push_back(pick);
  }
  std::stable_sort(plan.picks.begin(), plan.picks.end(), [](const Pick& a, const Pick& b) { return a.rank > b.rank; });
  return plan;
}

PickPlan truthPickPlan(const std::vector<TruthInstance>& truth, const std::vector<TemplateBank>& banks,
                       const std::vector<std::vector<Grasp>>& grasps, const cv::Mat& depth_m, const Camera& camera,
                       const std::optional<BinBox>& bin, const PickParams& params, float min_visib) {
  std::vector<Detection> instances;
  for (const TruthInstance& t : truth) {
    Detection d;
    d.bank = t.bank;
    d.object = banks.at(static_cast<std::size_t>(t.bank)).object;
    d.score = 1.f;
    d.pose = t.pose;
    instances.push_back(d);
  }
  PickPlan plan = planPicks(instances, banks, grasps, depth_m, camera, bin, params);
  std::erase_if(plan.picks, [&](const Pick& p) { return truth[static_cast<std::size_t>(p.detection)].visib_fract < min_visib; });
  return plan;
}

std::string firstPickProblem(const PickPlan& plan, const std::vector<Detection>& detections,
                             const std::vector<TemplateBank>& banks, const std::vector<TruthInstance>& truth,
                             const std::optional<BinBox>& bin, float max_error) {
  if (plan.picks.empty()) return "no pick";
  const Pick& pick = plan.picks.front();
  const Detection& d = detections.at(static_cast<std::size_t>(pick.detection));
  const TemplateBank& bank = banks.at(static_cast<std::size_t>(d.bank));
  const float spacing = std::clamp(bank.diameter / 30.f, 0.001f, 0.003f);
  const PlacedPart picked = placePart(d, bank, spacing);
  // The true instance the detection is: the nearest of its object within max_error (ADI).
  int matched = -1;
  float best = max_error * bank.diameter;
  std::vector<std::vector<Eigen::Vector3f>> others;
  std::vector<std::string> names;
  for (std::size_t k = 0; k < truth.size(); ++k) {
    const TemplateBank& tb = banks.at(static_cast<std::size_t>(truth[k].bank));
    Detection at;
    at.pose = truth[k].pose;
    PlacedPart part = placePart(at, tb, std::clamp(tb.diameter / 30.f, 0.001f, 0.003f));
    if (truth[k].bank == d.bank && (part.centre - picked.centre).norm() < bank.diameter) {
      const NearestNeighbours index(part.points, 0.005f);
      double sum = 0;
      for (const Eigen::Vector3f& p : picked.points) {
        float sqr = 0.f;
        index.nearest(p, sqr);
        sum += std::sqrt(sqr);
      }
      const float adi = static_cast<float>(sum / static_cast<double>(std::max<std::size_t>(picked.points.size(), 1)));
      if (adi < best) best = adi, matched = static_cast<int>(k);
    }
    others.push_back(std::move(part.points));
    names.push_back(fmt::format("true instance {} ({})", k, tb.object));
  }
  if (matched < 0) return fmt::format("detection {} ({}) is no true instance", pick.detection + 1, d.object);
  others.erase(others.begin() + matched);
  names.erase(names.begin() + matched);
  const std::string hit = gripperCollision(pick.grasp.source, pick.grasp.pose, bin, others, names);
  return hit.empty() ? std::string() : "the gripper " + hit;
}

}  // namespace vkpose
