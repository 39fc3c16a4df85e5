// Stage 8's acceptance rules and the competition between poses (accept.hpp).
#include "pose/accept.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <utility>

#include <Eigen/Geometry>
#include <fmt/format.h>

#include "pose/verify.hpp"

namespace vkpose {

namespace {

/// Where a pose puts a point of the object's frame (the bank's centre, mostly).
Eigen::Vector3f placed(const Pose& pose, const Eigen::Vector3f& point) { return pose.R * point + pose.t; }

/// What decides between two verified poses of one object in one place: the score, times the
/// dense fit of the chosen look-alike alternative (its depth fit, colour and depth residual
/// over the whole mask) where that check ran. On the small-part bins a bracket turned over
/// a real one scored 0.58-0.78 against 0.47-0.72 for the right pose, but fit densely 0.25-0.76
/// against 0.63-0.93.
float sameObjectRank(const Detection& d) {
  const auto& alts = d.look_alike_alternatives;
  const auto chosen = static_cast<std::size_t>(d.look_alike_chosen);
  return chosen < alts.size() ? d.score * alts[chosen].score : d.score;
}

bool samePlace(const Detection& a, const Detection& b, const std::vector<TemplateBank>& banks,
               float duplicate_fraction) {
  return samePlace(a.pose, static_cast<std::size_t>(a.bank), b.pose, static_cast<std::size_t>(b.bank), banks,
                   duplicate_fraction);
}

/// The image box and centre of the posed visible model.
void placeInImage(Detection& d, const PointCloud& model_points, const Eigen::Vector3f& centre, const Camera& camera) {
  cv::Rect2f box;
  bool first = true;
  for (const auto& p : model_points) {
    const Eigen::Vector3f c = placed(d.pose, p);
    if (!(c.z() > 0.f)) continue;
    const Eigen::Vector2f uv = camera.project(c);
    const cv::Rect2f px(uv.x(), uv.y(), 1.f, 1.f);
    box = first ? px : (box | px);
    first = false;
  }
  if (!first) d.bbox = box;
  const Eigen::Vector3f c = placed(d.pose, centre);
  if (c.z() > 0.f) {
    const Eigen::Vector2f uv = camera.project(c);
    d.x = uv.x();
    d.y = uv.y();
  }
}

/// The candidate's Detection at a fit (its refinement, or its first fit) with stage 8's
/// evidence there.
Detection fittedDetection(const PoseCandidate& c, const RefineResult& fit, const PoseEvidence& e,
                          const TemplateBank& bank, const Camera& camera) {
  Detection d = c.detection;
  d.pose = fit.pose;
  d.icp_fitness = fit.fitness;
  d.icp_iterations = fit.iterations;
  d.collision_rate = e.collision.collision_rate;
  d.see_through = e.depth.seen_through;
  d.depth_fit = e.depth.fits;
  d.silhouette_support = e.silhouette_support;
  d.contour_edges = e.contour_edges;
  d.outline_on_edges = e.outline_on_edges;
  d.silhouette_scale = e.silhouette_scale;
  d.score = poseScore(e);
  placeInImage(d, c.initial.model_points, bank.centre, camera);
  return d;
}

/// The detection among `kept` whose place `d` takes, or nullptr.
const Detection* takenPlace(const Detection& d, const std::vector<Detection>& kept,
                            const std::vector<TemplateBank>& banks, float duplicate_fraction) {
  for (const auto& k : kept)
    if (samePlace(k, d, banks, duplicate_fraction)) return &k;
  return nullptr;
}

/// Objects compete for the scene, best score first: a detection in the place of a better one,
/// or whose explained cells (cells[k] of accepted[k]) are mostly claimed by better ones, goes.
void competeForScene(std::vector<Detection>& accepted, const std::vector<std::vector<int>>& cells,
                     const std::vector<TemplateBank>& banks, const DetectorParams& params, DetectionResult& result) {
  std::vector<std::size_t> order(accepted.size());
  for (std::size_t k = 0; k < order.size(); ++k) order[k] = k;
  std::stable_sort(order.begin(), order.end(),
                   [&](std::size_t a, std::size_t b) { return accepted[a].score > accepted[b].score; });
  std::map<int, std::size_t> claimed;  // scene cell -> index into result.detections
  for (const std::size_t a : order) {
    Detection& d = accepted[a];
    if (const Detection* taken = takenPlace(d, result.detections, banks, params.duplicate_fraction))
      d.rejection = fmt::format("the same place as a better {} detection", taken->object);
    if (!d.rejection.empty()) {
      d.verified = false;
      result.rejected.push_back(std::move(d));
      continue;
    }
    // The better detection that claimed most of this one's scene, and how much it claimed.
    std::map<std::size_t, std::size_t> shared_with;
    std::size_t shared = 0;
    for (const int cell : cells[a])
      if (const auto it = claimed.find(cell); it != claimed.end()) ++shared, ++shared_with[it->second];
    const float share = cells[a].empty() ? 0.f : static_cast<float>(shared) / static_cast<float>(cells[a].size());
    if (share > params.verify.max_shared_support) {
      const auto most = std::max_element(shared_with.begin(), shared_with.end(),
                                         [](const auto& x, const auto& y) { return x.second < y.second; });
      d.verified = false;
      d.rejection = fmt::format("{:.0f}% of the scene it explains is explained by better detections (at most {:.0f}%), "
                                "most by a {} detection",
                                100 * share, 100 * params.verify.max_shared_support,
                                result.detections[most->first].object);
      result.rejected.push_back(std::move(d));
      continue;
    }
    for (const int cell : cells[a]) claimed.emplace(cell, result.detections.size());
    result.detections.push_back(std::move(d));
  }
}

}  // namespace

bool samePlace(const Pose& a, std::size_t bank_a, const Pose& b, std::size_t bank_b,
               const std::vector<TemplateBank>& banks, float duplicate_fraction) {
  const TemplateBank& ba = banks.at(bank_a);
  const TemplateBank& bb = banks.at(bank_b);
  return (placed(a, ba.centre) - placed(b, bb.centre)).norm() < duplicate_fraction * std::min(ba.diameter, bb.diameter);
}

bool samePose(const Pose& a, const Pose& b, const TemplateBank& bank, float distance_fraction, float angle_deg) {
  return (placed(a, bank.centre) - placed(b, bank.centre)).norm() <= distance_fraction * bank.diameter &&
         Eigen::AngleAxisf(a.R.transpose() * b.R).angle() <= angle_deg * static_cast<float>(M_PI) / 180.f;
}

float poseScore(float collision_rate, float see_through, float silhouette_support) {
  return collision_rate * (1.f - see_through) * silhouette_support;
}

float poseScore(const PoseEvidence& e) {
  return poseScore(e.collision.collision_rate, e.depth.seen_through, e.silhouette_support);
}

float unhiddenCollisionRate(const PoseEvidence& e, const VerifyParams& vp) {
  const float unhidden = unhiddenShare(e.depth.occluded, vp.occlusion_credit);
  return unhidden > 0.f ? e.collision.collision_rate / unhidden : e.collision.collision_rate;
}

namespace {
/// Stage 8's collision test (VerifyResult::accepted with the hidden points left out).
bool collisionAccepted(const PoseEvidence& e, const VerifyParams& vp) {
  return e.collision.model_points > 0 && unhiddenCollisionRate(e, vp) > vp.threshold;
}
}  // namespace

bool collides(const PoseCandidate& c) { return c.measured && collisionAccepted(c.evidence, c.verify); }

bool hopeless(const PoseCandidate& c) {
  return c.evidence.silhouette_support < c.verify.hopeless_support_share * c.verify.min_silhouette_support;
}

void markTwins(std::vector<PoseCandidate>& candidates, const std::vector<TemplateBank>& banks,
               const VerifyParams& params) {
  std::vector<std::size_t> order;
  for (std::size_t i = 0; i < candidates.size(); ++i)
    if (collides(candidates[i])) order.push_back(i);
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    return poseScore(candidates[a].evidence) > poseScore(candidates[b].evidence);
  });
  std::vector<std::size_t> kept;
  for (const std::size_t i : order) {
    PoseCandidate& c = candidates[i];
    const TemplateBank& bank = banks[c.bank()];
    const Pose& p = c.refined.pose;
    for (const std::size_t k : kept) {
      if (candidates[k].bank() != c.bank() ||
          !samePose(p, candidates[k].refined.pose, bank, params.twin_distance_fraction, params.twin_angle_deg))
        continue;
      c.twin = true;
      break;
    }
    if (!c.twin) kept.push_back(i);
  }
}

std::string stageEightShortfall(const PoseCandidate& c) {
  const VerifyParams& vp = c.verify;
  const PoseEvidence& e = c.evidence;
  const float see_through = e.depth.seen_through;
  if (!collisionAccepted(e, vp))
    return fmt::format("collision rate {:.2f} ({:.2f} of the points the scene does not hide) is not above {:.2f}",
                       e.collision.collision_rate, unhiddenCollisionRate(e, vp), vp.threshold);
  if (see_through > vp.max_see_through)
    return fmt::format("the camera sees through {:.0f}% of the model (at most {:.0f}%)", 100 * see_through,
                       100 * vp.max_see_through);
  if (e.silhouette_support < vp.min_silhouette_support)
    return fmt::format("only {:.0f}% of the outline shows a depth step (at least {:.0f}%)",
                       100 * e.silhouette_support, 100 * vp.min_silhouette_support);
  if (e.contour_edges < vp.min_contour_edges)
    return fmt::format("only {:.0f}% of its visible outline meets an edge in the image (at least {:.0f}%): "
                       "something else of its size?",
                       100 * e.contour_edges, 100 * vp.min_contour_edges);
  if (e.outline_on_edges < vp.min_outline_on_edges)
    return fmt::format("only {:.0f}% of its visible outline lies on an image edge within 1.5 px (at least {:.0f}%): "
                       "something else of its size, or a pose off the part?",
                       100 * e.outline_on_edges, 100 * vp.min_outline_on_edges);
  if (vp.max_silhouette_scale > 0.f && e.silhouette_scale > vp.max_silhouette_scale)
    return fmt::format("the scene's silhouette around it is {:.0f}% larger than the model (at most {:.0f}%): a larger "
                       "look-alike?",
                       100 * (e.silhouette_scale - 1.f), 100 * (vp.max_silhouette_scale - 1.f));
  if (e.scaled_outline_support > e.outlineSupport() + vp.size_probe_margin)
    return fmt::format("its outline fits better 15% larger or smaller ({:.0f}% against {:.0f}% at its own size): "
                       "a look-alike of another size?",
                       100 * e.scaled_outline_support, 100 * e.outlineSupport());
  return {};
}

std::string rejectionReason(const PoseCandidate& c, const std::string& object) {
  const VerifyParams& vp = c.verify;
  const Detection& d = c.detection;
  if (c.twin) return fmt::format("the same pose as a better {} candidate", object);
  if (std::string shortfall = stageEightShortfall(c); !shortfall.empty()) return shortfall;
  if (d.colour_agreement < vp.min_colour_agreement)
    return fmt::format("its colours do not match the scene's (agreement {:.2f}, at least {:.2f}): "
                       "something else of its shape?",
                       d.colour_agreement, vp.min_colour_agreement);
  return {};
}

void rejectSameObjectDuplicates(std::vector<Detection>& verified, const std::vector<TemplateBank>& banks,
                                float duplicate_fraction) {
  std::vector<std::size_t> order(verified.size());
  for (std::size_t k = 0; k < order.size(); ++k) order[k] = k;
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    return sameObjectRank(verified[a]) > sameObjectRank(verified[b]);
  });
  std::vector<std::size_t> kept;
  for (const std::size_t x : order) {
    Detection& d = verified[x];
    if (!d.rejection.empty()) continue;
    const auto better = std::find_if(kept.begin(), kept.end(), [&](std::size_t y) {
      return verified[y].bank == d.bank && samePlace(verified[y], d, banks, duplicate_fraction);
    });
    if (better == kept.end())
      kept.push_back(x);
    else
      d.rejection = fmt::format("the same place as a better {} detection", verified[*better].object);
  }
}

void acceptPoses(std::vector<PoseCandidate>& candidates, const std::vector<TemplateBank>& banks,
                 const Camera& camera, const DetectorParams& params, DetectionResult& result) {
  std::vector<Detection> accepted;
  std::vector<std::vector<int>> accepted_cells;  // the explained cells of accepted[k]
  for (PoseCandidate& c : candidates) {
    const TemplateBank& bank = banks[c.bank()];
    if (!c.initial.ok) {
      Detection d = std::move(c.detection);
      d.pose = c.start;
      d.rejection = c.initial.why;
      result.rejected.push_back(std::move(d));
      continue;
    }
    if (!c.screened.empty()) {  // reported at its first fit, with what was measured there
      Detection d = fittedDetection(c, c.first_fit, c.first_evidence, bank, camera);
      d.rejection = c.screened;
      result.rejected.push_back(std::move(d));
      continue;
    }
    Detection d = fittedDetection(c, c.refined, c.evidence, bank, camera);
    d.rejection = rejectionReason(c, bank.object);
    if (!d.rejection.empty()) {
      result.rejected.push_back(std::move(d));
      continue;
    }
    d.verified = true;
    accepted.push_back(std::move(d));
    accepted_cells.push_back(std::move(c.evidence.explained));
  }
  // Two poses in one place: the better one stays (NMS works on image centres; after ICP two
  // clusters of one instance can meet). First among one object's own poses, ranked by the
  // score times the dense fit its look-alike check measured where it ran (sameObjectRank);
  // then across objects by the score alone (only some objects have that fit).
  rejectSameObjectDuplicates(accepted, banks, params.duplicate_fraction);
  competeForScene(accepted, accepted_cells, banks, params, result);
}

}  // namespace vkpose
