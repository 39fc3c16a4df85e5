// Stage 6: initial rotation from the templates of a hypothesis, initial translation from the
// centroids of the scene and rendered points under the rendered mask.
#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

#include <Eigen/Geometry>
#include <fmt/format.h>

#include "hypotheses/hypotheses.hpp"
#include "match/matcher.hpp"
#include "pose/initial_pose.hpp"
#include "render/render.hpp"
#include "vkpose/bank.hpp"
#include "vkpose/error.hpp"
#include "vkpose/geometry.hpp"

namespace vkpose {

float rotationDistance(const Eigen::Matrix3f& a, const Eigen::Matrix3f& b) {
  // trace(A^T B) = 1 + 2 cos(angle); clamped against rounding just outside [-1, 1].
  const float c = std::clamp(0.5f * ((a.transpose() * b).trace() - 1.f), -1.f, 1.f);
  return std::acos(c);
}

Eigen::Matrix3f meanRotation(const std::vector<Eigen::Matrix3f>& rotations, const std::vector<float>& weights) {
  if (rotations.empty()) return Eigen::Matrix3f::Identity();
  const Eigen::Quaternionf first(rotations.front());
  Eigen::Vector4f sum = Eigen::Vector4f::Zero();
  for (std::size_t i = 0; i < rotations.size(); ++i) {
    Eigen::Quaternionf q(rotations[i]);
    if (q.dot(first) < 0.f) q.coeffs() = -q.coeffs();
    sum += (weights.empty() ? 1.f : weights[i]) * q.coeffs();
  }
  if (sum.norm() < 1e-12f) return rotations.front();
  Eigen::Quaternionf mean;
  mean.coeffs() = sum.normalized();
  return mean.toRotationMatrix();
}

std::vector<RotationGroup> clusterRotations(const std::vector<Eigen::Matrix3f>& rotations, float max_angle_rad,
                                            const std::vector<float>& weights) {
  auto weightOf = [&](int i) { return weights.empty() ? 1.f : weights[static_cast<std::size_t>(i)]; };
  std::vector<RotationGroup> groups;
  for (int i = 0; i < static_cast<int>(rotations.size()); ++i) {
    const Eigen::Matrix3f& R = rotations[static_cast<std::size_t>(i)];
    RotationGroup* nearest = nullptr;
    float nearest_angle = max_angle_rad;
    for (auto& g : groups)
      if (const float a = rotationDistance(g.mean, R); a < nearest_angle) nearest_angle = a, nearest = &g;
    if (!nearest) {
      groups.push_back({R, {i}, weightOf(i)});
      continue;
    }
    nearest->members.push_back(i);
    nearest->weight += weightOf(i);
    std::vector<Eigen::Matrix3f> rs;
    std::vector<float> ws;
    for (int m : nearest->members) {
      rs.push_back(rotations[static_cast<std::size_t>(m)]);
      ws.push_back(weightOf(m));
    }
    nearest->mean = meanRotation(rs, ws);
  }
  std::stable_sort(groups.begin(), groups.end(), [](const RotationGroup& a, const RotationGroup& b) {
    return a.members.size() != b.members.size() ? a.members.size() > b.members.size() : a.weight > b.weight;
  });
  return groups;
}

InitialRotation initialRotation(const Hypothesis& h, const TemplateBank& bank, const Camera& camera,
                                const InitialPoseParams& params, const ScoreParams& score, int starts) {
  std::vector<Eigen::Matrix3f> rotations;
  std::vector<float> weights;
  for (const ClusterMember& m : h.members) {  // best similarity first
    const BankTemplate& t = bank.templates.at(static_cast<std::size_t>(m.template_index));
    rotations.push_back(viewingRayRotation(m.centre_x, m.centre_y, camera) * t.pose.R);
    weights.push_back(m.similarity);
  }
  InitialRotation out;
  out.candidates = static_cast<int>(rotations.size());
  if (rotations.empty()) return out;
  const auto groups = clusterRotations(rotations, params.rotation_cluster_deg * static_cast<float>(M_PI) / 180.f,
                                       weights);
  out.R = groups.front().mean;
  out.group_size = static_cast<int>(groups.front().members.size());
  const std::size_t started = std::min(groups.size(), static_cast<std::size_t>(std::max(starts, 1)));
  for (std::size_t g = 1; g < started; ++g) {
    out.more.push_back({groups[g].mean, static_cast<int>(groups[g].members.size())});
  }
  for (std::size_t g = started; g < groups.size(); ++g)  // the one group that holds member 0
    if (std::find(groups[g].members.begin(), groups[g].members.end(), 0) != groups[g].members.end()) {
      out.by_best_match = RotationStart{groups[g].mean, static_cast<int>(groups[g].members.size())};
      break;
    }
  if (!params.second_start_by_fit) return out;
  // The scored members again, each weighted by its own fit to the scene (stage 4's), groups
  // ranked by the sum.
  std::vector<Eigen::Matrix3f> fitted;
  std::vector<float> fits;
  for (std::size_t k = 0; k < std::min(h.members.size(), h.member_scores.size()); ++k) {
    const MemberScore& s = h.member_scores[k];
    if (s.object_cells == 0 || s.normal_pairs == 0) continue;
    fitted.push_back(rotations[k]);
    fits.push_back(s.fit(score));
  }
  if (fitted.empty()) return out;
  const float tau = params.rotation_cluster_deg * static_cast<float>(M_PI) / 180.f;
  const auto by_fit = clusterRotations(fitted, tau, fits);
  const auto best = std::max_element(by_fit.begin(), by_fit.end(),
                                     [](const RotationGroup& a, const RotationGroup& b) { return a.weight < b.weight; });
  if (rotationDistance(best->mean, out.R) <= tau) return out;
  for (const RotationStart& s : out.more)
    if (rotationDistance(best->mean, s.R) <= tau) return out;
  out.by_fit = RotationStart{best->mean, static_cast<int>(best->members.size())};
  return out;
}

Pose poseOnViewingRay(const Eigen::Matrix3f& R, const Hypothesis& h, const TemplateBank& bank, const Camera& camera,
                      bool range_along_ray) {
  // The training camera looked at bank.centre, so the centre's range is the template's; the
  // cluster score measured how far the scene surface is from the template's (depth_offset).
  float range = h.distance;
  if (h.best_member >= 0 && static_cast<std::size_t>(h.best_member) < h.members.size()) {
    const auto best = static_cast<std::size_t>(h.best_member);
    const BankTemplate& t = bank.templates.at(static_cast<std::size_t>(h.members[best].template_index));
    range = (t.pose.R * bank.centre + t.pose.t).norm();
    const float offset = best < h.member_scores.size() ? h.member_scores[best].depth_offset : 0.f;
    range = range_along_ray ? rangeOnRay(range, offset, h.x, h.y, camera) : range + offset;
  }
  return poseAtRange(R, h.x, h.y, range, bank.centre, camera);
}

float rangeOnRay(float template_range, float depth_offset, float x, float y, const Camera& camera) {
  const Eigen::Vector3f ray = camera.ray(x, y);
  return (template_range + depth_offset) * ray.norm();  // ray.norm() = 1 / cos(theta)
}

Pose poseAtRange(const Eigen::Matrix3f& R, float x, float y, float range, const Eigen::Vector3f& centre,
                 const Camera& camera) {
  const Eigen::Vector3f ray = camera.ray(x, y);
  Pose p;
  p.R = R;
  p.t = ray.normalized() * range - R * centre;
  return p;
}

cv::Rect projectedWindow(const Pose& pose, const Eigen::Vector3f& centre, float radius, const Camera& camera,
                         int margin_px) {
  const Eigen::Vector3f c = pose.R * centre + pose.t;
  const cv::Rect image(0, 0, camera.width, camera.height);
  if (!(c.z() > radius) || !c.allFinite()) return {};  // reaches behind the camera
  // The sphere's image is an ellipse inside the circle of radius f r / (z - r) around the
  // projected centre (the projection of its nearest cross-section bounds it).
  const Eigen::Vector2f uv = camera.project(c);
  const float scale = radius / (c.z() - radius);
  const FloatIntrinsics k = camera.floatIntrinsics();
  const float rx = k.fx * scale * (1.f + std::abs(c.x()) / c.z()) + static_cast<float>(margin_px);
  const float ry = k.fy * scale * (1.f + std::abs(c.y()) / c.z()) + static_cast<float>(margin_px);
  const float x0 = std::max(uv.x() - rx, -1.f), y0 = std::max(uv.y() - ry, -1.f);
  const float x1 = std::min(uv.x() + rx, static_cast<float>(camera.width) + 1.f),
              y1 = std::min(uv.y() + ry, static_cast<float>(camera.height) + 1.f);
  if (!(x0 < x1 && y0 < y1)) return {};
  const cv::Rect box(static_cast<int>(std::floor(x0)), static_cast<int>(std::floor(y0)),
                     static_cast<int>(std::ceil(x1) - std::floor(x0)) + 1, static_cast<int>(std::ceil(y1) - std::floor(y0)) + 1);
  return box & image;
}

Camera windowCamera(const Camera& camera, const cv::Rect& window) {
  Camera w = camera;
  w.cx = camera.cx - window.x;
  w.cy = camera.cy - window.y;
  w.width = window.width;
  w.height = window.height;
  return w;
}

PointCloud visibleModelPoints(const Rendering& rendering, const Pose& pose, const Camera& camera,
                              const cv::Rect& window) {
  PointCloud out;
  const Eigen::Matrix3f R_inv = pose.R.transpose();
  for (int v = window.y; v < window.y + window.height; ++v) {
    const float* zr = rendering.depth.ptr<float>(v - window.y);
    for (int u = window.x; u < window.x + window.width; ++u) {
      const float z = zr[u - window.x];
      if (!(z > 0.f)) continue;
      const Eigen::Vector3f pm = camera.backProject(u, v, z);
      out.push_back(R_inv * (pm - pose.t));
    }
  }
  return out;
}

namespace {

/// The rendered object's pixels in the window: their count, box (scene pixels) and depth range.
struct RenderedExtent {
  std::size_t pixels = 0;
  cv::Rect box;
  float z_min = std::numeric_limits<float>::max(), z_max = 0.f;
};

RenderedExtent renderedExtent(const cv::Mat& rendered_depth, const cv::Rect& window) {
  RenderedExtent e;
  for (int v = window.y; v < window.y + window.height; ++v) {
    const float* zr = rendered_depth.ptr<float>(v - window.y);
    for (int u = window.x; u < window.x + window.width; ++u) {
      const float z = zr[u - window.x];
      if (!(z > 0.f)) continue;
      ++e.pixels;
      e.box |= cv::Rect(u, v, 1, 1);
      e.z_min = std::min(e.z_min, z);
      e.z_max = std::max(e.z_max, z);
    }
  }
  return e;
}

/// The scene crop around the model rendered at `centre` and moved by `shift`: its box (moved
/// by the move's projection) grown by the margin, depths within the band of its moved depth
/// range.
PointCloud sceneCrop(const cv::Mat& scene_depth_m, const Camera& camera, const RenderedExtent& extent,
                     const Eigen::Vector3f& centre, const Eigen::Vector3d& shift, float margin_fraction, float band) {
  const cv::Rect& box = extent.box;
  const Eigen::Vector3f centre_after = centre + shift.cast<float>();
  const Eigen::Vector2f image_shift = camera.project(centre_after) - camera.project(centre);
  const int mx = static_cast<int>(std::ceil(margin_fraction * static_cast<float>(box.width)));
  const int my = static_cast<int>(std::ceil(margin_fraction * static_cast<float>(box.height)));
  cv::Rect crop(box.x + static_cast<int>(std::lround(image_shift.x())) - mx,
                box.y + static_cast<int>(std::lround(image_shift.y())) - my, box.width + 2 * mx, box.height + 2 * my);
  crop &= cv::Rect(0, 0, scene_depth_m.cols, scene_depth_m.rows);
  const float near = extent.z_min + static_cast<float>(shift.z()) - band;
  const float far = extent.z_max + static_cast<float>(shift.z()) + band;
  PointCloud points;
  for (int v = crop.y; v < crop.y + crop.height; ++v) {
    const float* zs = scene_depth_m.ptr<float>(v);
    for (int u = crop.x; u < crop.x + crop.width; ++u)
      if (zs[u] > near && zs[u] < far) points.push_back(camera.backProject(u, v, zs[u]));
  }
  return points;
}

}  // namespace

InitialPose initialTranslation(const Rendering& rendering, const Pose& rendered, const cv::Mat& scene_depth_m,
                               const Camera& camera, float diameter, const InitialPoseParams& params,
                               const cv::Rect& window_in) {
  const cv::Rect window = window_in.empty() ? cv::Rect(0, 0, scene_depth_m.cols, scene_depth_m.rows) : window_in;
  if (rendering.depth.size() != window.size() || rendering.depth.type() != CV_32FC1 ||
      scene_depth_m.type() != CV_32FC1 || (window & cv::Rect(0, 0, scene_depth_m.cols, scene_depth_m.rows)) != window)
    throw InputError(fmt::format("initial translation: a {}x{} rendering for a {}x{} window of a {}x{} scene depth "
                                 "(both CV_32FC1)",
                                 rendering.depth.cols, rendering.depth.rows, window.width, window.height,
                                 scene_depth_m.cols, scene_depth_m.rows));
  const float band = params.depth_band_fraction * diameter;
  auto backProject = [&](int u, int v, float z) { return camera.backProject(u, v, z); };
  InitialPose out;
  out.pose = rendered;
  Eigen::Vector3d scene_sum = Eigen::Vector3d::Zero(), model_sum = Eigen::Vector3d::Zero();
  std::size_t model_count = 0;
  out.model_points = visibleModelPoints(rendering, rendered, camera, window);
  const RenderedExtent extent = renderedExtent(rendering.depth, window);
  out.mask_pixels = extent.pixels;
  if (out.mask_pixels == 0) {
    out.why = "the model renders outside the image";
    return out;
  }
  // The pixels that pair the rendering with the scene when the rendering is moved `dz` along
  // the camera's axis: the moved depths choose the pairs, the centroids stay the unmoved
  // model's, so the shift below carries the move. `differences` collects scene minus rendered
  // depth under the mask.
  auto pair = [&](float dz, std::vector<float>* differences) {
    scene_sum.setZero();
    model_sum.setZero();
    model_count = 0;
    out.object_pixels = 0;
    for (int v = window.y; v < window.y + window.height; ++v) {
      const float* zr = rendering.depth.ptr<float>(v - window.y);
      const float* zs = scene_depth_m.ptr<float>(v);
      for (int u = window.x; u < window.x + window.width; ++u) {
        const float z = zr[u - window.x];
        if (!(z > 0.f)) continue;
        if (differences && zs[u] > 0.f) differences->push_back(zs[u] - z);
        const float zm = z + dz;
        if (!(zs[u] > 0.f) || zs[u] < zm - band) continue;  // no depth, or an occluder
        model_sum += backProject(u, v, z).cast<double>();
        ++model_count;
        if (zs[u] > zm + band) continue;  // background seen past the object's edge
        scene_sum += backProject(u, v, zs[u]).cast<double>();
        ++out.object_pixels;
      }
    }
  };
  pair(0.f, nullptr);
  // A start more than the band short or long (the template's range is a z-range, and off the
  // optical axis the range along the ray is longer; a lying object's template can sit a few
  // centimetres off its centre) pairs no pixel. It gets a second try, moved by the median
  // depth difference under its mask: gathered by pairing once more, only here, since nearly
  // every start pairs at once.
  if (out.object_pixels < params.min_scene_points) {
    std::vector<float> differences;
    pair(0.f, &differences);
    if (differences.size() >= params.min_scene_points) {
      const auto mid = differences.begin() + static_cast<std::ptrdiff_t>(differences.size() / 2);
      std::nth_element(differences.begin(), mid, differences.end());
      if (std::abs(*mid) > band) {
        pair(*mid, nullptr);
        out.second_try_m = *mid;
      }
    }
  }
  if (out.object_pixels < params.min_scene_points) {
    out.why = fmt::format("{} of the {} pixels under the model have scene depth near it (at least {} needed)",
                          out.object_pixels, out.mask_pixels, params.min_scene_points);
    return out;
  }
  const Eigen::Vector3d shift = scene_sum / static_cast<double>(out.object_pixels) -
                                model_sum / static_cast<double>(model_count);
  out.pose.t = rendered.t + shift.cast<float>();

  out.scene_points = sceneCrop(scene_depth_m, camera, extent, rendered.t, shift, params.crop_margin_fraction, band);
  out.ok = true;
  return out;
}

}  // namespace vkpose
