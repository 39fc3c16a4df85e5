// Stages 6-8 over one frame's candidates (candidate.hpp): the per-candidate functions of
// initial_pose, refine and verify, run for all of a frame's candidates.
#include "pose/candidate.hpp"

#include <algorithm>
#include <chrono>

#include <fmt/format.h>

#include "pose/accept.hpp"
#include "pose/alternatives.hpp"
#include "pose/appearance.hpp"
#include "render/render.hpp"
#include "util/parallel.hpp"
#include "util/timing.hpp"

namespace vkpose {

/// What stages 6-8 know of each bank's object, but its renderer (Detector::attachRenderers).
std::vector<PoseObject> poseObjects(const std::vector<TemplateBank>& banks, const DetectorParams& params) {
  std::vector<PoseObject> objects(banks.size());
  for (std::size_t b = 0; b < banks.size(); ++b) {
    objects[b].bank = &banks[b];
    for (const auto& v : banks[b].mesh.vertices)
      objects[b].bounding_radius = std::max(objects[b].bounding_radius, (v - banks[b].centre).norm());
    objects[b].colourful = meshChromaSpread(banks[b].mesh) >= kMinChromaSpread;
  }
  // Look-alike half-turns: about 0.1 s a mesh, so found here rather than stored (banks of
  // every version get them, and the tolerance stays a detection setting).
  if (params.verify.resolve_symmetries)
    util::parallelFor(
        banks.size(),
        [&](std::size_t b) {
          const TemplateBank& bank = banks[b];
          if (bank.symmetric) return;  // scored with ADI: turns do not count against it
          const float from = std::max(bank.params.near_symmetry_tolerance, 0.01f) * bank.diameter;
          const float share = isSmallPart(bank.diameter) ? params.verify.small_part_look_alike_tolerance
                                                         : params.verify.look_alike_tolerance;
          objects[b].look_alike_turns = findLookAlikeTurns(bank.mesh, from, share * bank.diameter);
        },
        params.threads);
  return objects;
}

using util::msSince;

namespace {

/// fn(c) for each candidate of `which` (indices), on `threads` threads, each call's time
/// added to the candidate's cpu_ms.
template <class Fn>
void forEachOf(std::vector<PoseCandidate>& candidates, const std::vector<std::size_t>& which, unsigned threads,
               Fn&& fn) {
  util::parallelFor(
      which.size(),
      [&](std::size_t k) {
        PoseCandidate& c = candidates[which[k]];
        const auto start = std::chrono::steady_clock::now();
        fn(c);
        c.cpu_ms += msSince(start);
      },
      threads);
}

/// Pose i of objects[banks[i]] rendered in its own window of the frame (projectedWindow;
/// an empty window, the model outside the image: an empty rendering), each object's in one
/// call through a camera per pose: a submit per object and batch where a render each was a
/// submit each (on LM-O 359 starts), the same pixels.
struct WindowRenderings {
  std::vector<Rendering> renderings;
  std::vector<cv::Rect> windows;
};
WindowRenderings renderInWindows(const std::vector<PoseObject>& objects, const Camera& camera,
                                 const std::vector<std::size_t>& banks, const std::vector<Pose>& poses,
                                 RenderedImages images) {
  std::vector<cv::Rect> windows(poses.size());
  for (std::size_t i = 0; i < poses.size(); ++i) {
    const PoseObject& o = objects[banks[i]];
    windows[i] = projectedWindow(poses[i], o.bank->centre, o.bounding_radius, camera);
  }
  std::vector<Rendering> out(poses.size());
  for (std::size_t b = 0; b < objects.size(); ++b) {
    std::vector<std::size_t> ids;
    std::vector<Camera> cameras;
    std::vector<Pose> chosen;
    for (std::size_t i = 0; i < poses.size(); ++i)
      if (banks[i] == b && !windows[i].empty()) {
        ids.push_back(i);
        cameras.push_back(windowCamera(camera, windows[i]));
        chosen.push_back(poses[i]);
      }
    if (ids.empty()) continue;
    std::vector<Rendering> rendered = objects[b].renderer->render(cameras, chosen, images);
    for (std::size_t k = 0; k < ids.size(); ++k) out[ids[k]] = std::move(rendered[k]);
  }
  return {std::move(out), std::move(windows)};
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
                                            const Camera& camera, const DetectorParams& params, int starts,
                                            bool best_match_start) {
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
  if (best_match_start && rot.by_best_match) start(rot.by_best_match->R, rot.by_best_match->votes);
  return out;
}

VerifyParams partVerifyParams(VerifyParams verify, const TemplateBank& bank) {
  const bool small = isSmallPart(bank.diameter);
  if (small || bank.params.views.radii.low() >= kPileDistanceM) verify.max_silhouette_scale = 0.f;
  if (!small) return verify;
  verify.min_colour_agreement = verify.small_part_min_colour_agreement;
  if (bank.symmetric || revolutionAxis(bank.near_symmetries))
    verify.min_outline_on_edges = std::max(verify.min_outline_on_edges, verify.small_turned_part_min_outline_on_edges);
  return verify;
}

void initialPoses(std::vector<PoseCandidate>& candidates, const std::vector<PoseObject>& objects,
                  const PoseFrame& frame, const DetectorParams& params) {
  const Camera& camera = frame.camera;
  const std::size_t n = candidates.size();
  // Rendering is the GPU's, in the calling thread, depth alone (all initialTranslation reads);
  // the translations run in parallel. An empty window: initialTranslation says why.
  std::vector<std::size_t> banks(n);
  std::vector<Pose> starts(n);
  for (std::size_t i = 0; i < n; ++i) {
    banks[i] = candidates[i].bank();
    starts[i] = candidates[i].start;
  }
  auto [renderings, windows] = renderInWindows(objects, camera, banks, starts, RenderedImages::depth);
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
    const TemplateBank& bank = *objects[c.bank()].bank;
    const DetectorParams scaled = scaledForObject(params, bank.diameter, c.start.t.z());
    c.refine = scaled.refine;
    c.verify = partVerifyParams(scaled.verify, bank);
    // A second try's raised limit keeps the first fit's margin under the plain one: on the
    // tuning sets, what MLS and ICP add to a second try's collision rate stayed under 0.07.
    c.first_fit_min_collision = c.refine.first_fit_share * c.verify.threshold;
    if (c.initial.second_try_m != 0.f) {
      const float raised = std::max(c.verify.threshold, params.verify.second_try_min_collision);
      c.first_fit_min_collision += raised - c.verify.threshold;
      c.verify.threshold = raised;
    }
  }
}

void firstFits(std::vector<PoseCandidate>& candidates, const PoseFrame& frame, unsigned threads) {
  std::vector<std::size_t> placed;
  for (std::size_t i = 0; i < candidates.size(); ++i)
    if (candidates[i].initial.ok) placed.push_back(i);
  forEachOf(candidates, placed, threads, [&](PoseCandidate& c) {
    RefineParams unsmoothed = c.refine;
    unsmoothed.mls = false;
    c.first_fit = refinePose(c.initial.model_points, c.initial.scene_points, c.initial.pose, unsmoothed,
                             FinePoints::Thinned);
    c.first_evidence =
        measurePose(c.initial.model_points, c.first_fit.pose, c.initial.scene_points, frame, c.verify, false);
  });
}

namespace {

/// The stage 8 limit a first fit falls short of by more than its share allows, or empty.
/// A start above the collision limit that sees through first_fit_pulled_see_through or more
/// of itself keeps its see-through and silhouette tests for stage 8: a large object on a
/// table, pulled by the table, can see through 25 % of itself and show a third of its
/// outline at the first fit and pass every test after MLS and ICP (synthetic milk cartons).
std::string firstFitShortfall(const PoseCandidate& c) {
  const PoseEvidence& e = c.first_evidence;
  const RefineParams& rp = c.refine;
  const VerifyParams& vp = c.verify;
  const float share = rp.first_fit_share;
  const float collision = unhiddenCollisionRate(e, vp);
  if (collision < c.first_fit_min_collision)
    return fmt::format("collision rate {:.2f} of the points the scene does not hide after the first fit (at least "
                       "{:.2f} to go on)",
                       collision, c.first_fit_min_collision);
  if (e.contour_edges < rp.first_fit_contour_share * vp.min_contour_edges)
    return fmt::format("only {:.0f}% of its visible outline meets an edge in the image after the first fit (at "
                       "least {:.0f}% to go on)",
                       100 * e.contour_edges, 100 * rp.first_fit_contour_share * vp.min_contour_edges);
  if (collision >= vp.threshold && e.depth.seen_through >= rp.first_fit_pulled_see_through) return {};
  if (share > 0.f && e.depth.seen_through > vp.max_see_through / share)
    return fmt::format("the camera sees through {:.0f}% of the model after the first fit (at most {:.0f}% to go on)",
                       100 * e.depth.seen_through, 100 * vp.max_see_through / share);
  if (e.silhouette_support < rp.first_fit_silhouette_share * vp.min_silhouette_support)
    return fmt::format("only {:.0f}% of the outline shows a depth step after the first fit (at least {:.0f}% to go on)",
                       100 * e.silhouette_support, 100 * rp.first_fit_silhouette_share * vp.min_silhouette_support);
  return {};
}

}  // namespace

void screenStarts(std::vector<PoseCandidate>& candidates) {
  for (PoseCandidate& c : candidates)
    if (c.initial.ok && c.refine.first_fit) c.screened = firstFitShortfall(c);
}

void firstFitColours(std::vector<PoseCandidate>& candidates, const std::vector<PoseObject>& objects,
                     const PoseFrame& frame, unsigned threads) {
  std::vector<std::size_t> which;
  for (std::size_t i = 0; i < candidates.size(); ++i) {
    const PoseCandidate& c = candidates[i];
    if (c.refinable() && c.refine.first_fit && !objects[c.bank()].bank->mesh.colours.empty() &&
        c.verify.min_colour_agreement > -1.f)
      which.push_back(i);
  }
  // Rendering is the GPU's, in the calling thread (as stage 6's).
  std::vector<std::size_t> banks(which.size());
  std::vector<Pose> poses(which.size());
  for (std::size_t k = 0; k < which.size(); ++k) {
    banks[k] = candidates[which[k]].bank();
    poses[k] = candidates[which[k]].first_fit.pose;
  }
  auto [views, windows] = renderInWindows(objects, frame.camera, banks, poses, RenderedImages::all);
  util::parallelFor(
      which.size(),
      [&](std::size_t k) {
        PoseCandidate& c = candidates[which[k]];
        if (windows[k].empty()) return;
        const auto start = std::chrono::steady_clock::now();
        const AppearanceAgreement a = appearanceAgreement(views[k], windows[k], frame.bgr, frame.depth_m,
                                                          c.verify.see_through_tolerance, true);
        views[k] = {};
        if (a.colour_informative) c.first_colour = a.colour;
        c.cpu_ms += msSince(start);
      },
      threads);
  for (const std::size_t i : which) {
    PoseCandidate& c = candidates[i];
    const float limit = c.verify.min_colour_agreement - c.refine.first_fit_colour_margin;
    if (c.first_colour < limit)  // false for NaN: colours that said too little stop nothing
      c.screened = fmt::format("its colours do not match the scene's after the first fit (agreement {:.2f}, at least "
                               "{:.2f} to go on)",
                               c.first_colour, limit);
  }
}

std::vector<std::size_t> nextRound(std::vector<PoseCandidate>& candidates, const std::vector<TemplateBank>& banks,
                                   float duplicate_fraction) {
  // Without the first fit every start goes at once; with it, best first (ties keep the
  // stage 6 order), the measured ones taking part as the better ones they may be.
  std::vector<std::size_t> order, round;
  for (std::size_t i = 0; i < candidates.size(); ++i) {
    const PoseCandidate& c = candidates[i];
    if (c.refinable() && c.refine.first_fit)
      order.push_back(i);
    else if (c.refinable() && !c.measured)
      round.push_back(i);
  }
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    return poseScore(candidates[a].first_evidence) > poseScore(candidates[b].first_evidence);
  });
  for (std::size_t k = 0; k < order.size(); ++k) {
    PoseCandidate& c = candidates[order[k]];
    if (c.measured) continue;
    const TemplateBank& bank = banks[c.bank()];
    int same_object = 0;
    bool waits = false, twin = false;
    const PoseCandidate* passed = nullptr;
    for (std::size_t j = 0; j < k && !passed && !twin; ++j) {
      const PoseCandidate& better = candidates[order[j]];
      if (!better.screened.empty() ||
          !samePlace(better.first_fit.pose, better.bank(), c.first_fit.pose, c.bank(), banks, duplicate_fraction))
        continue;
      if (better.bank() == c.bank()) {
        ++same_object;  // refined alongside: the first fit's ranking is not the final one
        twin = samePose(better.first_fit.pose, c.first_fit.pose, bank, c.verify.twin_distance_fraction,
                        c.refine.first_fit_twin_angle_deg);
      } else if (!better.measured) {
        waits = true;
      } else if (stageEightShortfall(better).empty()) {
        passed = &better;
      }
    }
    if (twin)
      c.screened = fmt::format("the same pose after the first fit as a better start of {}", bank.object);
    else if (passed)
      c.screened = fmt::format("a better start of {} in the same place passed stage 8 after the first fit",
                               banks[passed->bank()].object);
    else if (c.refine.first_fit_per_place > 0 && same_object >= c.refine.first_fit_per_place)
      c.screened = fmt::format("{} better starts of {} in the same place after the first fit", same_object, bank.object);
    else if (!waits)
      round.push_back(order[k]);
  }
  std::sort(round.begin(), round.end());  // stage 6's order
  return round;
}

void smoothSceneCrops(std::vector<PoseCandidate>& candidates, const std::vector<std::size_t>& round,
                      unsigned threads) {
  forEachOf(candidates, round, threads, [](PoseCandidate& c) {
    const RefineParams& rp = c.refine;
    c.smoothed = rp.mls ? smoothMls(c.initial.scene_points, rp.mls_radius, rp.mls_polynomial_order,
                                    rp.mls_at_voxel_seeds ? rp.voxel_size : 0.f, rp.mls_max_neighbours)
                        : c.initial.scene_points;
  });
}

void refineCandidates(std::vector<PoseCandidate>& candidates, const std::vector<std::size_t>& round,
                      unsigned threads) {
  forEachOf(candidates, round, threads, [](PoseCandidate& c) {
    RefineParams icp_params = c.refine;
    icp_params.mls = false;  // smoothSceneCrops did it
    c.refined = refinePose(c.initial.model_points, c.smoothed, c.initial.pose, icp_params);
  });
}

namespace {
/// PoseEvidence::scaled_outline_support: the best outline support of `model` (camera frame)
/// scaled by 1/1.15 and by 1.15 about its centroid, and moved across the view by the size
/// change either way (ICP lays the part against one side of a look-alike of another size).
float scaledOutlineSupport(const PointCloud& model, const PoseFrame& frame, const VerifyParams& params) {
  Eigen::Vector3f centre = Eigen::Vector3f::Zero();
  for (const auto& p : model) centre += p;
  centre /= static_cast<float>(std::max<std::size_t>(1, model.size()));
  float radius = 0.f;  // across the view
  for (const auto& p : model) radius = std::max(radius, (p - centre).head<2>().norm());
  float best = 0.f;
  for (const float s : {1.f / 1.15f, 1.15f}) {
    const float shift = std::abs(s - 1.f) * radius;
    for (const Eigen::Vector3f& d : {Eigen::Vector3f(0.f, 0.f, 0.f), Eigen::Vector3f(shift, 0.f, 0.f),
                                     Eigen::Vector3f(-shift, 0.f, 0.f), Eigen::Vector3f(0.f, shift, 0.f),
                                     Eigen::Vector3f(0.f, -shift, 0.f)}) {
      PointCloud scaled(model.size());
      for (std::size_t i = 0; i < model.size(); ++i) scaled[i] = centre + d + s * (model[i] - centre);
      const auto outline = outlineSamples(scaled, frame.camera, frame.depth_m.size());
      best = std::max(best, PoseEvidence::outlineSupport(
                                contourEdgeSupport(outline, frame.edges, frame.depth_m, params.silhouette_jump),
                                silhouetteSupport(outline, frame.depth_m, params.silhouette_jump, params.occlusion_credit)));
    }
  }
  return best;
}
}  // namespace

PoseEvidence measurePose(const PointCloud& model_points, const Pose& pose, const PointCloud& scene_points,
                         const PoseFrame& frame, const VerifyParams& params, bool with_cells) {
  const PointCloud model = transformed(model_points, pose);
  PoseEvidence e;
  e.collision = verifyPose(model, scene_points, params);
  e.depth = depthAgreement(model, frame.depth_m, frame.camera, params.see_through_tolerance);
  const auto outline = outlineSamples(model, frame.camera, frame.depth_m.size());
  e.silhouette_support = silhouetteSupport(outline, frame.depth_m, params.silhouette_jump, params.occlusion_credit);
  e.contour_edges = contourEdgeSupport(outline, frame.edges, frame.depth_m, params.silhouette_jump);
  e.outline_on_edges = outlineOnEdges(outline, frame.edges, frame.depth_m, params.silhouette_jump);
  if (with_cells) {
    e.silhouette_scale = silhouetteScale(outline, frame.depth_m, params.silhouette_jump);
    e.explained = supportCells(model, frame.depth_m, frame.camera, params.see_through_tolerance);
    if (params.size_probe_margin < 1.f) e.scaled_outline_support = scaledOutlineSupport(model, frame, params);
  }
  return e;
}

void verifyCandidate(PoseCandidate& c, const PoseFrame& frame) {
  const auto start = std::chrono::steady_clock::now();
  c.evidence = measurePose(c.initial.model_points, c.refined.pose, c.initial.scene_points, frame, c.verify);
  c.measured = true;
  c.cpu_ms += msSince(start);
}

void verifyCandidates(std::vector<PoseCandidate>& candidates, const std::vector<std::size_t>& round,
                      const PoseFrame& frame, unsigned threads) {
  util::parallelFor(
      round.size(), [&](std::size_t k) { verifyCandidate(candidates[round[k]], frame); }, threads);
}

}  // namespace vkpose
