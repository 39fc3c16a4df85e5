// Stages 6-8 over one frame's candidates (candidate.hpp): the per-candidate functions of
// initial_pose, refine and verify, run for all of a frame's candidates.
#include "pose/candidate.hpp"

#include <algorithm>
#include <chrono>

#include <fmt/format.h>

#include "pose/accept.hpp"
#include "render/render.hpp"
#include "util/parallel.hpp"
#include "util/timing.hpp"

namespace vkpose {

using util::msSince;

namespace {

/// fn(c) for each candidate that `goes_on` (stage 6 placed it, or the first fit did not stop
/// it either), on `threads` threads, each call's time added to the candidate's cpu_ms.
template <class Fn>
void forEachPlaced(std::vector<PoseCandidate>& candidates, unsigned threads, Fn&& fn,
                   bool (*goes_on)(const PoseCandidate&) = [](const PoseCandidate& c) { return c.refinable(); }) {
  util::parallelFor(
      candidates.size(),
      [&](std::size_t i) {
        PoseCandidate& c = candidates[i];
        if (!goes_on(c)) return;
        const auto start = std::chrono::steady_clock::now();
        fn(c);
        c.cpu_ms += msSince(start);
      },
      threads);
}

}  // namespace

PoseFrame poseFrame(const Camera& camera, const cv::Mat& depth_m, const cv::Mat& bgr) {
  PoseFrame frame;
  frame.camera = camera;
  frame.depth_m = depth_m;
  frame.bgr = bgr.type() == CV_8UC3 && bgr.size() == depth_m.size() ? bgr
                                                                     : cv::Mat(depth_m.size(), CV_8UC3, cv::Scalar::all(0));
  frame.edges = imageEdges(frame.bgr);
  return frame;
}

Detection hypothesisDetection(const Hypothesis& h, const std::vector<TemplateBank>& banks) {
  const TemplateBank& bank = banks[static_cast<std::size_t>(h.bank)];
  const ClusterMember& m = h.members[static_cast<std::size_t>(h.best_member)];
  Detection d;
  d.bank = h.bank;
  d.object = bank.object;
  d.score = h.score;
  d.gamma = h.score;
  d.alpha = h.alpha;
  d.beta = h.beta;
  d.x = h.x;
  d.y = h.y;
  d.bbox = templateBox(h, bank.templates[static_cast<std::size_t>(m.template_index)]);
  d.templates = static_cast<int>(h.members.size());
  d.template_index = m.template_index;
  d.similarity = m.similarity;
  return d;
}

std::vector<PoseCandidate> startCandidates(const std::vector<Hypothesis>& hypotheses,
                                           const std::vector<TemplateBank>& banks, const Camera& camera,
                                           const DetectorParams& params) {
  const InitialPoseParams& ip = params.initial_pose;
  std::vector<PoseCandidate> candidates;
  for (const Hypothesis& h : hypotheses) {
    const TemplateBank& bank = banks[static_cast<std::size_t>(h.bank)];
    const int starts = std::max(isSmallPart(bank.diameter) ? ip.small_part_starts : 1,
                                bank.params.views.other_ups.empty() ? 1 : ip.resting_poses_starts);
    for (PoseCandidate& c : hypothesisStarts(h, banks, camera, params, starts)) candidates.push_back(std::move(c));
  }
  return candidates;
}

std::vector<PoseCandidate> hypothesisStarts(const Hypothesis& h, const std::vector<TemplateBank>& banks,
                                            const Camera& camera, const DetectorParams& params, int starts) {
  const InitialPoseParams& ip = params.initial_pose;
  const TemplateBank& bank = banks[static_cast<std::size_t>(h.bank)];
  const InitialRotation rot = initialRotation(h, bank, camera, ip, params.score, starts);
  std::vector<PoseCandidate> out;
  const auto start = [&](const Eigen::Matrix3f& R, int votes) {
    PoseCandidate& c = out.emplace_back();
    c.detection = hypothesisDetection(h, banks);
    c.detection.rotation_votes = votes;
    c.start = poseOnViewingRay(R, h, bank, camera, ip.range_along_ray);
  };
  start(rot.R, rot.group_size);
  for (const RotationStart& s : rot.more) start(s.R, s.votes);
  if (rot.by_fit) start(rot.by_fit->R, rot.by_fit->votes);
  return out;
}

void initialPoses(std::vector<PoseCandidate>& candidates, const std::vector<PoseObject>& objects,
                  const PoseFrame& frame, const DetectorParams& params) {
  const Camera& camera = frame.camera;
  const std::size_t n = candidates.size();
  // Rendering is the GPU's, one submit a candidate in the calling thread; the translations
  // run in parallel.
  std::vector<Rendering> renderings(n);
  std::vector<cv::Rect> windows(n);
  for (std::size_t i = 0; i < n; ++i) {
    const PoseObject& o = objects[candidates[i].bank()];
    windows[i] = projectedWindow(candidates[i].start, o.bank->centre, o.bounding_radius, camera);
    if (windows[i].empty()) continue;  // initialTranslation says why
    renderings[i] = std::move(o.renderer->render(windowCamera(camera, windows[i]), {candidates[i].start}).front());
  }
  util::parallelFor(
      n,
      [&](std::size_t i) {
        PoseCandidate& c = candidates[i];
        if (windows[i].empty()) {
          c.initial.pose = c.start;
          c.initial.why = "the model renders outside the image";
          return;
        }
        const float diameter = objects[c.bank()].bank->diameter;
        c.initial = initialTranslation(renderings[i], c.start, frame.depth_m, camera, diameter, params.initial_pose,
                                       windows[i]);
        renderings[i] = {};
      },
      params.threads);
  // The lengths of stages 7-8 for each candidate's object at its distance (scaledForObject:
  // the defaults for objects of 10 cm and more), and a small part's own colour test.
  for (PoseCandidate& c : candidates) {
    const float diameter = objects[c.bank()].bank->diameter;
    const DetectorParams scaled = scaledForObject(params, diameter, c.start.t.z());
    c.refine = scaled.refine;
    c.verify = scaled.verify;
    if (isSmallPart(diameter)) c.verify.min_colour_agreement = params.verify.small_part_min_colour_agreement;
    if (c.initial.second_try_m != 0.f)
      c.verify.threshold = std::max(c.verify.threshold, params.verify.second_try_min_collision);
  }
}

void firstFits(std::vector<PoseCandidate>& candidates, const PoseFrame& frame, unsigned threads) {
  forEachPlaced(
      candidates, threads,
      [&](PoseCandidate& c) {
        RefineParams unsmoothed = c.refine;
        unsmoothed.mls = false;
        c.first_fit = refinePose(c.initial.model_points, c.initial.scene_points, c.initial.pose, unsmoothed,
                                 FinePoints::Thinned);
        const PointCloud model = transformed(c.initial.model_points, c.first_fit.pose);
        PoseEvidence& e = c.first_evidence;
        e.collision = verifyPose(model, c.initial.scene_points, c.verify);
        e.depth = depthAgreement(model, frame.depth_m, frame.camera, c.verify.see_through_tolerance);
        e.silhouette_support = silhouetteSupport(outlineSamples(model, frame.camera, frame.depth_m.size()),
                                                 frame.depth_m, c.verify.silhouette_jump);
      },
      [](const PoseCandidate& c) { return c.initial.ok; });
}

namespace {

/// The stage 8 limit a first fit falls short of by more than `share`, or empty. The see-through
/// and silhouette tests stop only a start whose collision rate is below stage 8's limit too:
/// a large object on a table, pulled by the table in the coarse stage, can see through 25 % of
/// itself and show a third of its outline at the first fit and pass every test after the fine
/// stage (synthetic milk cartons), while its collision rate is already above the limit.
std::string firstFitShortfall(const PoseEvidence& e, const VerifyParams& vp, float share) {
  const float collision = e.collision.collision_rate;
  if (collision < share * vp.threshold)
    return fmt::format("collision rate {:.2f} after the first fit (at least {:.2f} to go on)", collision,
                       share * vp.threshold);
  if (collision >= vp.threshold) return {};
  if (share > 0.f && e.depth.seen_through > vp.max_see_through / share)
    return fmt::format("the camera sees through {:.0f}% of the model after the first fit (at most {:.0f}% to go on)",
                       100 * e.depth.seen_through, 100 * vp.max_see_through / share);
  if (e.silhouette_support < share * vp.min_silhouette_support)
    return fmt::format("only {:.0f}% of the outline shows a depth step after the first fit (at least {:.0f}% to go on)",
                       100 * e.silhouette_support, 100 * share * vp.min_silhouette_support);
  return {};
}

Eigen::Vector3f placedCentre(const Pose& pose, const TemplateBank& bank) { return pose.R * bank.centre + pose.t; }

}  // namespace

void screenStarts(std::vector<PoseCandidate>& candidates, const std::vector<TemplateBank>& banks,
                  float duplicate_fraction) {
  std::vector<std::size_t> order;
  for (std::size_t i = 0; i < candidates.size(); ++i) {
    PoseCandidate& c = candidates[i];
    if (!c.initial.ok || !c.refine.first_fit) continue;
    c.screened = firstFitShortfall(c.first_evidence, c.verify, c.refine.first_fit_share);
    if (c.screened.empty()) order.push_back(i);
  }
  // Best first; ties keep the stage 6 order, so the result does not depend on the threads.
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    return poseScore(candidates[a].first_evidence) > poseScore(candidates[b].first_evidence);
  });
  std::vector<std::size_t> going_on;
  for (const std::size_t i : order) {
    PoseCandidate& c = candidates[i];
    const TemplateBank& bank = banks[c.bank()];
    const Eigen::Vector3f centre = placedCentre(c.first_fit.pose, bank);
    int better = 0;
    for (const std::size_t k : going_on)
      if (candidates[k].bank() == c.bank() &&
          (placedCentre(candidates[k].first_fit.pose, bank) - centre).norm() < duplicate_fraction * bank.diameter)
        ++better;
    if (c.refine.first_fit_per_place > 0 && better >= c.refine.first_fit_per_place)
      c.screened = fmt::format("{} better starts of {} in the same place after the first fit", better, bank.object);
    else
      going_on.push_back(i);
  }
}

void smoothSceneCrops(std::vector<PoseCandidate>& candidates, unsigned threads) {
  forEachPlaced(candidates, threads, [](PoseCandidate& c) {
    const RefineParams& rp = c.refine;
    c.smoothed = rp.mls ? smoothMls(c.initial.scene_points, rp.mls_radius, rp.mls_polynomial_order,
                                    rp.mls_at_voxel_seeds ? rp.voxel_size : 0.f, rp.mls_max_neighbours)
                        : c.initial.scene_points;
  });
}

void refineCandidates(std::vector<PoseCandidate>& candidates, unsigned threads) {
  forEachPlaced(candidates, threads, [](PoseCandidate& c) {
    RefineParams icp_params = c.refine;
    icp_params.mls = false;  // smoothSceneCrops did it
    c.refined = refinePose(c.initial.model_points, c.smoothed, c.initial.pose, icp_params);
  });
}

PoseEvidence measurePose(const PointCloud& model_points, const Pose& pose, const PointCloud& scene_points,
                         const PoseFrame& frame, const VerifyParams& params) {
  const PointCloud model = transformed(model_points, pose);
  PoseEvidence e;
  e.collision = verifyPose(model, scene_points, params);
  e.depth = depthAgreement(model, frame.depth_m, frame.camera, params.see_through_tolerance);
  const auto outline = outlineSamples(model, frame.camera, frame.depth_m.size());
  e.silhouette_support = silhouetteSupport(outline, frame.depth_m, params.silhouette_jump);
  e.contour_edges = contourEdgeSupport(outline, frame.edges, frame.depth_m, params.silhouette_jump);
  e.explained = supportCells(model, frame.depth_m, frame.camera, params.see_through_tolerance);
  return e;
}

void verifyCandidate(PoseCandidate& c, const PoseFrame& frame) {
  const auto start = std::chrono::steady_clock::now();
  c.evidence = measurePose(c.initial.model_points, c.refined.pose, c.initial.scene_points, frame, c.verify);
  c.cpu_ms += msSince(start);
}

void verifyCandidates(std::vector<PoseCandidate>& candidates, const PoseFrame& frame, unsigned threads) {
  util::parallelFor(
      candidates.size(),
      [&](std::size_t i) {
        if (candidates[i].refinable()) verifyCandidate(candidates[i], frame);
      },
      threads);
}

}  // namespace vkpose
