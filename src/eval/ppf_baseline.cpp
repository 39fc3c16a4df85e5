// The point-pair-feature baseline (Drost et al., CVPR 2010) through OpenCV's surface_matching:
// a PPF3DDetector per object trained on points sampled on its mesh, matched against the
// back-projected depth image, then OpenCV's ICP on the best-voted poses.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <random>

#include <Eigen/SVD>
#include <fmt/format.h>
#include <opencv2/surface_matching.hpp>
#include <opencv2/surface_matching/ppf_helpers.hpp>

#include "eval/baselines.hpp"
#include "hypotheses/cluster_score.hpp"
#include "hypotheses/cluster_score_math.hpp"
#include "match/matcher.hpp"
#include "util/timing.hpp"
#include "vkpose/detector.hpp"
#include "vkpose/error.hpp"
#include "vkpose/geometry.hpp"

namespace vkpose {

namespace {
using util::msSince;
namespace ppf = cv::ppf_match_3d;

Eigen::Vector3f rowPoint(const cv::Mat& pc, int i) {
  const float* r = pc.ptr<float>(i);
  return {r[0], r[1], r[2]};
}

/// The scene as OpenCV's PPF reads it: rows of x y z nx ny nz (metres, camera frame, normals
/// towards the camera), every pixel_step-th pixel with a depth and a normal.
cv::Mat sceneCloud(const cv::Mat& depth_mm, const Camera& camera, const PpfParams& p) {
  const ScoreScene scene = makeScoreScene(depth_mm, camera);
  std::vector<cv::Vec6f> rows;
  for (int y = 0; y < depth_mm.rows; y += p.pixel_step)
    for (int x = 0; x < depth_mm.cols; x += p.pixel_step) {
      Eigen::Vector3f n;
      if (!score::sceneNormal(scene, x, y, p.normal_step_px, p.normal_max_jump_m, n)) continue;
      const float z = scene.depth_m.at<float>(y, x);
      const Eigen::Vector3f point = score::backProject(scene, x, y, z);
      rows.emplace_back(point.x(), point.y(), point.z(), n.x(), n.y(), n.z());
    }
  return cv::Mat(static_cast<int>(rows.size()), 6, CV_32F, rows.data()).clone();
}

/// OpenCV's pose with its rotation made orthonormal again (poses are products of many
/// incremental ICP steps).
Pose poseOf(const cv::Matx44d& m) {
  Eigen::Matrix3d R;
  Pose p;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) R(r, c) = m(r, c);
    p.t(r) = static_cast<float>(m(r, 3));
  }
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(R, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d D = Eigen::Matrix3d::Identity();
  D(2, 2) = (svd.matrixU() * svd.matrixV().transpose()).determinant() < 0 ? -1 : 1;
  p.R = (svd.matrixU() * D * svd.matrixV().transpose()).cast<float>();
  return p;
}

/// The scene points within `radius` of `centre` (ICP's target: the object's neighbourhood).
cv::Mat cropAround(const cv::Mat& scene, const Eigen::Vector3f& centre, float radius) {
  cv::Mat out;
  const float r2 = radius * radius;
  for (int i = 0; i < scene.rows; ++i)
    if ((rowPoint(scene, i) - centre).squaredNorm() <= r2) out.push_back(scene.row(i));
  return out;
}
}  // namespace

void validatePpfParams(const PpfParams& p) {
  auto fraction = [](float v, const char* name) {
    if (!(v > 0.f && v <= 1.f)) throw InputError(fmt::format("ppf: {} must be in (0, 1], not {}", name, v));
  };
  fraction(p.model_step, "model step");
  fraction(p.scene_step, "scene step");
  fraction(p.scene_ref_fraction, "scene reference fraction");
  if (p.angle_bins < 4 || p.angle_bins > 360) throw InputError("ppf: angle bins must be 4..360");
  if (p.model_samples < 100) throw InputError("ppf: model samples must be at least 100");
  if (p.max_scene_cells < 4 || p.max_scene_cells > 400) throw InputError("ppf: max scene cells must be 4..400");
  if (p.pixel_step < 1 || p.pixel_step > 32) throw InputError("ppf: pixel step must be 1..32");
  if (p.normal_step_px < 1 || p.normal_step_px > 16) throw InputError("ppf: normal step must be 1..16 pixels");
  if (!(p.normal_max_jump_m > 0.f)) throw InputError("ppf: normal depth jump must be positive");
  if (p.icp_poses < 0 || p.icp_iterations < 1 || p.icp_levels < 1 || p.icp_model_points < 10)
    throw InputError("ppf: ICP needs poses >= 0, iterations >= 1, levels >= 1 and at least 10 model points");
  if (!(p.icp_crop > 0.f)) throw InputError("ppf: ICP crop must be positive");
  if (p.max_poses < 1) throw InputError("ppf: max poses must be at least 1");
  if (!(p.duplicate_distance >= 0.f)) throw InputError("ppf: duplicate distance must be >= 0");
}

cv::Mat sampleMeshSurface(const Mesh& mesh, int count, unsigned seed) {
  if (mesh.faces.empty() || count < 1) throw InputError("cannot sample the surface of '" + mesh.name + "'");
  std::vector<double> cumulative;
  cumulative.reserve(mesh.faces.size());
  double total = 0;
  for (const auto& f : mesh.faces) {
    const Eigen::Vector3f &a = mesh.vertices[static_cast<std::size_t>(f.x())],
                          &b = mesh.vertices[static_cast<std::size_t>(f.y())],
                          &c = mesh.vertices[static_cast<std::size_t>(f.z())];
    total += 0.5 * static_cast<double>((b - a).cross(c - a).norm());
    cumulative.push_back(total);
  }
  // Uniform numbers from the raw engine (the standard distributions differ between libraries).
  std::mt19937 rng(seed);
  auto uniform = [&] { return static_cast<double>(rng() >> 8) / static_cast<double>(1u << 24); };
  cv::Mat out(count, 6, CV_32F);
  for (int i = 0; i < count; ++i) {
    const auto k = static_cast<std::size_t>(std::upper_bound(cumulative.begin(), cumulative.end(), uniform() * total) -
                                            cumulative.begin());
    const auto& f = mesh.faces[std::min(k, mesh.faces.size() - 1)];
    float u = static_cast<float>(uniform()), v = static_cast<float>(uniform());
    if (u + v > 1.f) u = 1.f - u, v = 1.f - v;
    const float w = 1.f - u - v;
    const auto ia = static_cast<std::size_t>(f.x()), ib = static_cast<std::size_t>(f.y()),
               ic = static_cast<std::size_t>(f.z());
    const Eigen::Vector3f p = w * mesh.vertices[ia] + u * mesh.vertices[ib] + v * mesh.vertices[ic];
    Eigen::Vector3f n = Eigen::Vector3f::Zero();
    if (mesh.normals.size() == mesh.vertices.size())
      n = w * mesh.normals[ia] + u * mesh.normals[ib] + v * mesh.normals[ic];
    if (n.norm() < 1e-6f) n = (mesh.vertices[ib] - mesh.vertices[ia]).cross(mesh.vertices[ic] - mesh.vertices[ia]);
    n.normalize();
    float* row = out.ptr<float>(i);
    for (int j = 0; j < 3; ++j) row[j] = p(j), row[3 + j] = n(j);
  }
  return out;
}

struct PpfBaseline::Model {
  int obj_id = 0;
  float diameter = 0.f;
  Eigen::Vector3f centre = Eigen::Vector3f::Zero();  ///< bounding-box centre, object frame
  cv::Mat icp_points;                                ///< rows x y z nx ny nz, object frame
  std::unique_ptr<ppf::PPF3DDetector> detector;
};

PpfBaseline::PpfBaseline(PpfParams params) : params_(params) { validatePpfParams(params_); }
PpfBaseline::~PpfBaseline() = default;

std::vector<int> PpfBaseline::objects() const {
  std::vector<int> ids;
  for (const auto& m : models_) ids.push_back(m->obj_id);
  return ids;
}

void PpfBaseline::addObject(int obj_id, const Mesh& mesh) {
  for (const auto& m : models_)
    if (m->obj_id == obj_id) throw InputError(fmt::format("ppf: object {} was added twice", obj_id));
  const auto t0 = std::chrono::steady_clock::now();
  auto model = std::make_unique<Model>();
  model->obj_id = obj_id;
  model->diameter = mesh.diameter;
  model->centre = mesh.bboxCentre();
  const cv::Mat samples = sampleMeshSurface(mesh, params_.model_samples);
  const int stride = std::max(1, samples.rows / params_.icp_model_points);
  for (int i = 0; i < samples.rows; i += stride) model->icp_points.push_back(samples.row(i));
  model->detector = std::make_unique<ppf::PPF3DDetector>(params_.model_step, params_.model_step, params_.angle_bins);
  // OpenCV's defaults cluster poses within 0.1 units of position (a model-unit guess) and a
  // rotation threshold above 2 pi (any rotation): set both for a model in metres.
  model->detector->setSearchParams(params_.cluster_distance * mesh.diameter,
                                   params_.cluster_angle_deg * 3.14159265358979 / 180.0, true);
  model->detector->trainModel(samples);
  models_.push_back(std::move(model));
  training_ms_ += msSince(t0);
}

PpfResult PpfBaseline::detect(const cv::Mat& depth_mm, const Camera& camera) const {
  if (depth_mm.empty() || depth_mm.type() != CV_16UC1) throw InputError("ppf: the depth image must be 16-bit millimetres");
  validateCamera(camera);
  PpfResult result;
  const auto total0 = std::chrono::steady_clock::now();
  const cv::Mat scene = sceneCloud(depth_mm, camera, params_);
  result.scene_points = static_cast<std::size_t>(scene.rows);
  result.scene_ms = msSince(total0);
  if (scene.rows < 16) {
    result.total_ms = msSince(total0);
    return result;
  }
  cv::Mat lo, hi;
  cv::reduce(scene.colRange(0, 3), lo, 0, cv::REDUCE_MIN);
  cv::reduce(scene.colRange(0, 3), hi, 0, cv::REDUCE_MAX);
  const float extent = static_cast<float>(cv::norm(hi - lo, cv::NORM_INF));

  ppf::ICP icp(params_.icp_iterations, 0.005f, 2.5f, params_.icp_levels);
  for (const auto& model : models_) {
    const auto t0 = std::chrono::steady_clock::now();
    // OpenCV samples the scene in cells of (its box's extent per axis) * step: the step that
    // gives cells of scene_step diameters on the longest axis, as fine as max_scene_cells allows.
    const double step = std::max(static_cast<double>(params_.scene_step * model->diameter / extent),
                                 1.0 / params_.max_scene_cells);
    std::vector<ppf::Pose3DPtr> poses;
    model->detector->match(scene, poses, params_.scene_ref_fraction, std::min(step, 1.0));
    if (poses.size() > static_cast<std::size_t>(params_.icp_poses)) poses.resize(static_cast<std::size_t>(params_.icp_poses));

    std::vector<PpfDetection> found;
    for (auto& pose : poses) {
      const Pose before = poseOf(pose->pose);
      const cv::Mat target = cropAround(scene, before.R * model->centre + before.t, params_.icp_crop * model->diameter);
      if (target.rows >= 16) {
        std::vector<ppf::Pose3DPtr> one{pose};
        icp.registerModelToScene(model->icp_points, target, one);
      }
      PpfDetection d;
      d.obj_id = model->obj_id;
      d.score = static_cast<float>(pose->numVotes);
      d.pose = poseOf(pose->pose);
      d.icp_residual = static_cast<float>(pose->residual);
      found.push_back(d);
    }
    // Best votes first; one pose per instance.
    std::stable_sort(found.begin(), found.end(), [](const auto& a, const auto& b) { return a.score > b.score; });
    std::vector<PpfDetection> kept;
    for (const auto& d : found) {
      if (static_cast<int>(kept.size()) >= params_.max_poses) break;
      const Eigen::Vector3f c = d.pose.R * model->centre + d.pose.t;
      const bool duplicate = std::any_of(kept.begin(), kept.end(), [&](const PpfDetection& k) {
        return (k.pose.R * model->centre + k.pose.t - c).norm() < params_.duplicate_distance * model->diameter;
      });
      if (!duplicate) kept.push_back(d);
    }
    result.detections.insert(result.detections.end(), kept.begin(), kept.end());
    result.object_ms[model->obj_id] = msSince(t0);
  }
  result.total_ms = msSince(total0);
  return result;
}

}  // namespace vkpose
