// One-to-one matching of estimates to ground truth and precision / recall / F1 (docs/evaluation.md,
// "The protocol").
#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

#include <fmt/format.h>

#include "eval/checks.hpp"
#include "vkpose/error.hpp"
#include "vkpose/evaluation.hpp"
#include "vkpose/geometry.hpp"

namespace vkpose {

EvalModel makeEvalModel(const ModelInfo& info, std::vector<Eigen::Vector3f> points) {
  if (points.empty()) throw InputError(fmt::format("object {}: no model points to score poses with", info.obj_id));
  if (!(info.diameter > 0))
    throw InputError(fmt::format("object {}: diameter {} must be positive", info.obj_id, info.diameter));
  return {info, PointIndex(std::move(points))};
}

std::map<int, EvalModel> loadEvalModels(const BopDataset& dataset) {
  std::map<int, EvalModel> out;
  for (const auto& [obj_id, info] : dataset.models)
    out.emplace(obj_id, makeEvalModel(info, loadMesh(dataset.evalModelPath(obj_id), MeshUnits::Millimetres).vertices));
  return out;
}

float proj2dError(const std::vector<Eigen::Vector3f>& points, const Eigen::Matrix3f& R_est, const Eigen::Vector3f& t_est,
                  const Eigen::Matrix3f& R_gt, const Eigen::Vector3f& t_gt, const Camera& camera) {
  if (points.empty()) return 0.f;
  double sum = 0;
  for (const Eigen::Vector3f& p : points) {
    const Eigen::Vector3f a = R_est * p + t_est, b = R_gt * p + t_gt;
    // A point at or behind the camera has no projection: count it as far off the image.
    if (!(a.z() > 1e-6f) || !(b.z() > 1e-6f)) {
      sum += 1e4;
      continue;
    }
    sum += (camera.project(a) - camera.project(b)).norm();
  }
  return static_cast<float>(sum / static_cast<double>(points.size()));
}

namespace {

/// Proj2D of a symmetric object (ADI's rule in the image): the mean, over the model points
/// projected under the truth, of the distance to the nearest point projected under the
/// estimate. At most 1,000 points each side (evenly taken): brute force stays cheap.
float symmetricProj2dError(const std::vector<Eigen::Vector3f>& points, const PoseEstimate& est,
                           const GroundTruthPose& gt, const Camera& camera) {
  const std::size_t step = std::max<std::size_t>(1, points.size() / 1000);
  std::vector<Eigen::Vector2f> seen, truth;
  for (std::size_t i = 0; i < points.size(); i += step) {
    const Eigen::Vector3f a = est.R * points[i] + est.t, b = gt.R * points[i] + gt.t;
    if (!(a.z() > 1e-6f) || !(b.z() > 1e-6f)) return 1e4f;  // behind the camera: no projection
    seen.push_back(camera.project(a));
    truth.push_back(camera.project(b));
  }
  if (truth.empty()) return 0.f;
  double sum = 0;
  for (const Eigen::Vector2f& q : truth) {
    float best = std::numeric_limits<float>::max();
    for (const Eigen::Vector2f& p : seen) best = std::min(best, (p - q).squaredNorm());
    sum += std::sqrt(best);
  }
  return static_cast<float>(sum / static_cast<double>(truth.size()));
}

}  // namespace

float poseError(const EvalModel& model, const PoseEstimate& est, const GroundTruthPose& gt, PoseErrorType type,
                const Camera* camera) {
  if (type == PoseErrorType::Proj2D) {
    if (!camera) throw InputError("the 2D projection error needs the image's camera");
    return model.info.symmetric ? symmetricProj2dError(model.points.points(), est, gt, *camera)
                                : proj2dError(model.points.points(), est.R, est.t, gt.R, gt.t, *camera);
  }
  if (type == PoseErrorType::Auto) type = model.info.symmetric ? PoseErrorType::ADI : PoseErrorType::ADD;
  return type == PoseErrorType::ADI ? adiError(model.points, est.R, est.t, gt.R, gt.t)
                                    : addError(model.points.points(), est.R, est.t, gt.R, gt.t);
}

ImageEvaluation evaluateImage(const std::vector<PoseEstimate>& estimates, const std::vector<GroundTruthPose>& gt,
                              const std::map<int, EvalModel>& models, const EvalParams& params,
                              const Camera* camera) {
  const auto modelOf = [&](int obj_id, const char* what, std::size_t index) -> const EvalModel& {
    const auto it = models.find(obj_id);
    if (it == models.end())
      throw InputError(fmt::format("{} {} is of object {}, which has no model", what, index, obj_id));
    return it->second;
  };
  for (std::size_t i = 0; i < estimates.size(); ++i) {
    modelOf(estimates[i].obj_id, "estimate", i);
    if (!std::isfinite(estimates[i].score) || !estimates[i].t.allFinite())
      throw InputError(fmt::format("estimate {} (object {}): the score and t must be finite", i, estimates[i].obj_id));
    if (const auto problem = eval::rotationProblem(estimates[i].R.cast<double>()))
      throw InputError(fmt::format("estimate {} (object {}): {}", i, estimates[i].obj_id, *problem));
  }
  for (std::size_t g = 0; g < gt.size(); ++g) modelOf(gt[g].obj_id, "ground-truth instance", g);

  ImageEvaluation result;
  result.matches.resize(estimates.size());
  // Best score first; equal scores keep the given order.
  std::vector<std::size_t> order(estimates.size());
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(),
                   [&](std::size_t a, std::size_t b) { return estimates[a].score > estimates[b].score; });

  std::vector<bool> taken(gt.size(), false);
  const auto counted = [&](std::size_t g) { return !(gt[g].visib_fract < params.min_visib_fract); };
  for (const std::size_t e : order) {
    const PoseEstimate& est = estimates[e];
    const EvalModel& model = models.at(est.obj_id);
    const float threshold =
        params.error == PoseErrorType::Proj2D ? params.proj2d_px : params.k_m * model.info.diameter;
    int best = -1;
    float best_error = 0.f;
    for (std::size_t g = 0; g < gt.size(); ++g) {
      if (taken[g] || gt[g].obj_id != est.obj_id) continue;
      const float err = poseError(model, est, gt[g], params.error, camera);
      if (err < threshold && (best < 0 || err < best_error)) {
        best = static_cast<int>(g);
        best_error = err;
      }
    }
    EvalCounts& c = result.counts[est.obj_id];
    EstimateMatch& m = result.matches[e];
    if (best < 0) {
      ++c.fp;
      continue;
    }
    taken[static_cast<std::size_t>(best)] = true;
    m.gt = best;
    m.error = best_error;
    m.ignored = !counted(static_cast<std::size_t>(best));
    if (!m.ignored) ++c.tp;
  }
  for (std::size_t g = 0; g < gt.size(); ++g) {
    EvalCounts& c = result.counts[gt[g].obj_id];  // every annotated object gets an entry
    VisibilityRecall& v = result.by_visibility[gt[g].obj_id];
    if (!counted(g)) continue;
    if (!taken[g]) ++c.fn;
    const int bin = VisibilityRecall::binOf(gt[g].visib_fract);
    ++v.instances[bin];
    if (taken[g]) ++v.found[bin];
  }
  return result;
}

int VisibilityRecall::binOf(float visib_fract) {
  // NaN goes to the lowest bin; 1.0 (and above) to the top one.
  const float v = std::isnan(visib_fract) ? 0.f : visib_fract;
  return std::clamp(static_cast<int>(std::floor(v * kBins)), 0, kBins - 1);
}

ObjectScores scoresOf(const EvalCounts& c) {
  ObjectScores s;
  s.tp = c.tp;
  s.fp = c.fp;
  s.fn = c.fn;
  s.precision = c.tp + c.fp > 0 ? static_cast<double>(c.tp) / (c.tp + c.fp) : 0.0;
  s.recall = c.tp + c.fn > 0 ? static_cast<double>(c.tp) / (c.tp + c.fn) : 0.0;
  s.f1 = s.precision + s.recall > 0 ? 2 * s.precision * s.recall / (s.precision + s.recall) : 0.0;
  return s;
}

EvalSummary summarize(const std::map<int, EvalCounts>& counts) {
  EvalSummary out;
  EvalCounts sum;
  for (const auto& [obj_id, c] : counts) {
    sum += c;
    const ObjectScores s = scoresOf(c);
    out.objects[obj_id] = s;
    out.mean.precision += s.precision;
    out.mean.recall += s.recall;
    out.mean.f1 += s.f1;
    out.mean.tp += s.tp;
    out.mean.fp += s.fp;
    out.mean.fn += s.fn;
  }
  if (!counts.empty()) {
    const auto n = static_cast<double>(counts.size());
    out.mean.precision /= n;
    out.mean.recall /= n;
    out.mean.f1 /= n;
  }
  out.total = scoresOf(sum);
  return out;
}

EvalSummary evaluateDataset(const BopDataset& dataset, const std::map<int, EvalModel>& models,
                            const std::vector<BopResult>& results, const EvalParams& params) {
  std::map<std::pair<int, int>, std::vector<PoseEstimate>> by_image;
  for (const auto& im : dataset.images) by_image[{im.scene_id, im.image_id}];
  for (std::size_t i = 0; i < results.size(); ++i) {
    const auto it = by_image.find({results[i].scene_id, results[i].im_id});
    if (it == by_image.end())
      throw InputError(fmt::format("result {}: scene {} image {} is not an annotated image of {} ({})", i,
                                   results[i].scene_id, results[i].im_id, dataset.root, dataset.split));
    it->second.push_back(results[i].estimate);
  }
  std::map<int, EvalCounts> counts;
  for (const auto& im : dataset.images) {
    try {
      const auto evaluation = evaluateImage(by_image.at({im.scene_id, im.image_id}), im.gt, models, params);
      for (const auto& [obj_id, c] : evaluation.counts) counts[obj_id] += c;
    } catch (const InputError& e) {
      throw InputError(fmt::format("scene {} image {}: {}", im.scene_id, im.image_id, e.what()));
    }
  }
  return summarize(counts);
}

}  // namespace vkpose
