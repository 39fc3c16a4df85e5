// Stage 8, render and compare (alternatives.hpp).
#include "pose/alternatives.hpp"

#include <algorithm>
#include <chrono>

#include "pose/accept.hpp"
#include "pose/appearance.hpp"
#include "render/render.hpp"
#include "util/parallel.hpp"
#include "util/timing.hpp"

namespace vkpose {

namespace {
using util::msSince;

/// Worth comparing: passed the collision test, not a twin, not hopeless.
bool worthComparing(const PoseCandidate& c) { return collides(c) && !c.twin && !hopeless(c); }

/// The window of the image that all `poses` of the object render in.
cv::Rect windowOf(const std::vector<Pose>& poses, const PoseObject& object, const Camera& camera) {
  cv::Rect window;
  for (const auto& p : poses) window |= projectedWindow(p, object.bank->centre, object.bounding_radius, camera);
  return window;
}

/// The candidate takes `pose` (rendered in `view` over `window`): its model points become that
/// rendering's, ICP's fine stage fits it once more from there unless `refit` is given, and it
/// is verified again.
void replacePose(PoseCandidate& c, const Rendering& view, const Pose& pose, const cv::Rect& window,
                 const PoseFrame& frame, const RefineResult* refit) {
  c.initial.model_points = visibleModelPoints(view, pose, frame.camera, window);
  if (refit) {
    c.refined = *refit;
  } else {
    RefineParams icp_params = c.refine;
    icp_params.mls = false;
    icp_params.coarse_iterations = 0;  // a turn of the surface onto itself: only the fine fit is left
    const auto start = std::chrono::steady_clock::now();
    c.refined = refinePose(c.initial.model_points, c.smoothed, pose, icp_params);
    c.cpu_ms += msSince(start);
  }
  verifyCandidate(c, frame);
}

/// Each turn of the pose refit from where it lands (mls off, as stage 7 already smoothed); the
/// refits' time goes to the candidate's cpu_ms.
std::vector<RefineResult> refitTurns(PoseCandidate& c, const PoseObject& object, const PoseFrame& frame,
                                     unsigned threads) {
  const auto& turns = object.look_alike_turns;
  std::vector<Pose> starts;
  for (const auto& h : turns) starts.push_back(compose(c.refined.pose, h.transform()));
  const cv::Rect window = windowOf(starts, object, frame.camera);
  if (window.empty()) return {};
  const auto views = object.renderer->render(windowCamera(frame.camera, window), starts);
  RefineParams icp_params = c.refine;
  icp_params.mls = false;
  std::vector<RefineResult> refits(turns.size());
  const auto start = std::chrono::steady_clock::now();
  util::parallelFor(
      turns.size(),
      [&](std::size_t k) {
        refits[k] = refinePose(visibleModelPoints(views[k], starts[k], frame.camera, window), c.smoothed, starts[k],
                               icp_params);
      },
      threads);
  c.cpu_ms += msSince(start);
  return refits;
}

/// The alternatives of a look-alike check: 0 the kept pose, g the refit of turns[g - 1], each
/// the best of its family (the refit and, where colour can tell them, its near-symmetric turns).
struct LookAlikeComparison {
  std::vector<SymmetryAlternative> alternatives;
  std::vector<std::size_t> member;  ///< the pose (index into the rendered poses) each alternative stands for
  bool informative = false;
};

LookAlikeComparison compareLookAlikes(const std::vector<Rendering>& views, const cv::Rect& window,
                                      const PoseObject& object, const PoseFrame& frame, float tolerance,
                                      std::size_t family) {
  const auto& turns = object.look_alike_turns;
  LookAlikeComparison out;
  out.alternatives.resize(1 + turns.size());
  out.member.assign(out.alternatives.size(), 0);
  auto& alts = out.alternatives;
  for (std::size_t k = 0; k < views.size(); ++k) {
    const AppearanceAgreement a =
        appearanceAgreement(views[k], window, frame.bgr, frame.depth_m, tolerance, object.colourful);
    SymmetryAlternative alt;
    const std::size_t g = k == 0 ? 0 : 1 + (k - 1) / family;  // 0: the kept pose, g: turns[g - 1]
    if (g > 0) alt.angle_deg = turns[g - 1].angle_deg, alt.axis = turns[g - 1].axis;
    alt.depth_fit = a.depth_fit;
    alt.colour = a.colour;
    alt.depth_residual_m = a.depth_residual_m;
    alt.score = a.score * std::max(0.f, 1.f - a.depth_residual_m / std::max(tolerance, 1e-6f));
    out.informative = out.informative || a.colour_informative;
    if (k == 0 || k == 1 + (g - 1) * family || alt.score > alts[g].score) alts[g] = alt, out.member[g] = k;
  }
  return out;
}

}  // namespace

std::pair<std::size_t, float> chooseAlternative(const std::vector<SymmetryAlternative>& alternatives, float margin) {
  const auto best = static_cast<std::size_t>(
      std::max_element(alternatives.begin(), alternatives.end(),
                       [](const auto& x, const auto& y) { return x.score < y.score; }) -
      alternatives.begin());
  float rival = -1.f;
  for (std::size_t k = 0; k < alternatives.size(); ++k)
    if (k != best) rival = std::max(rival, alternatives[k].score);
  const std::size_t chosen = best != 0 && alternatives[best].score >= alternatives[0].score + margin ? best : 0;
  return {chosen, alternatives[chosen].score - (chosen == best ? rival : alternatives[best].score)};
}

void resolveNearSymmetries(PoseCandidate& c, const PoseObject& object, const PoseFrame& frame,
                           const DetectorParams& params) {
  if (!worthComparing(c)) return;
  const TemplateBank& bank = *object.bank;
  const auto& symmetries = bank.near_symmetries;
  Detection& d = c.detection;
  const bool resolve = params.verify.resolve_symmetries && !symmetries.empty();
  if (!object.colourful && resolve) {
    // No colours that vary (none, or LM-O's scans, which vary too little): nothing to
    // compare the turns by but depth, and they fit it within the training tolerance by
    // construction (ICP has had its say): listed, not rendered (on IC-BIN rendering the
    // cup's 7 turns cost 230 ms a frame to say "ambiguous").
    d.symmetry_alternatives.resize(1 + symmetries.size());
    for (std::size_t k = 0; k < symmetries.size(); ++k) {
      d.symmetry_alternatives[k + 1].angle_deg = symmetries[k].angle_deg;
      d.symmetry_alternatives[k + 1].axis = symmetries[k].axis;
    }
    d.symmetry_compared = false;
    d.ambiguous_symmetry = true;
  }
  // Colours that vary too little to tell turns apart still tell the object from a
  // look-alike of another colour: then only the pose itself is rendered and compared.
  const bool turns = object.colourful && resolve;
  const bool colour_test = !bank.mesh.colours.empty() && c.verify.min_colour_agreement > -1.f;
  if (!turns && !colour_test) return;
  std::vector<Pose> poses{c.refined.pose};
  if (turns)
    for (const auto& s : symmetries) poses.push_back(compose(c.refined.pose, s.transform()));
  const cv::Rect window = windowOf(poses, object, frame.camera);
  if (window.empty()) return;
  const auto views = object.renderer->render(windowCamera(frame.camera, window), poses);
  std::vector<SymmetryAlternative> alts;
  bool informative = false;
  for (std::size_t k = 0; k < poses.size(); ++k) {
    const AppearanceAgreement a =
        appearanceAgreement(views[k], window, frame.bgr, frame.depth_m, c.verify.see_through_tolerance, true);
    SymmetryAlternative alt;
    if (k > 0) alt.angle_deg = symmetries[k - 1].angle_deg, alt.axis = symmetries[k - 1].axis;
    alt.depth_fit = a.depth_fit;
    alt.colour = a.colour;
    alt.score = a.score;
    alts.push_back(alt);
    informative = informative || a.colour_informative;
  }
  const float margin = params.verify.symmetry_margin;
  const auto [chosen, won_by] = chooseAlternative(alts, margin);
  if (informative) d.colour_agreement = alts[chosen].colour, d.colour_measured = true;
  if (turns) {
    d.symmetry_chosen = static_cast<int>(chosen);
    d.symmetry_margin = won_by;
    d.ambiguous_symmetry = d.symmetry_margin < margin;
    d.symmetry_alternatives = std::move(alts);
  }
  // The turned pose shows other faces of the model: ICP and verification take those.
  if (chosen != 0) replacePose(c, views[chosen], poses[chosen], window, frame, nullptr);
}

void resolveLookAlikes(PoseCandidate& c, const PoseObject& object, const PoseFrame& frame,
                       const DetectorParams& params) {
  const auto& turns = object.look_alike_turns;
  if (turns.empty() || !worthComparing(c)) return;
  const std::vector<RefineResult> refits = refitTurns(c, object, frame, params.threads);
  if (refits.empty()) return;
  // Each refit with the near-symmetries' turns too where colour can tell them (a carton
  // end for end shows another painted face on top): pose 0 is the kept one, then per
  // look-alike turn its refit composed with each near-symmetry.
  const bool compose_turns = object.colourful && params.verify.resolve_symmetries;
  const auto& symmetries = object.bank->near_symmetries;
  const std::size_t family = 1 + (compose_turns ? symmetries.size() : 0);
  std::vector<Pose> poses{c.refined.pose};
  for (const auto& r : refits) {
    poses.push_back(r.pose);
    if (compose_turns)
      for (const auto& sym : symmetries) poses.push_back(compose(r.pose, sym.transform()));
  }
  const cv::Rect window = windowOf(poses, object, frame.camera);
  if (window.empty()) return;
  const auto views = object.renderer->render(windowCamera(frame.camera, window), poses);
  LookAlikeComparison cmp = compareLookAlikes(views, window, object, frame, c.verify.see_through_tolerance, family);
  const auto [chosen, won_by] = chooseAlternative(cmp.alternatives, params.verify.symmetry_margin);
  Detection& d = c.detection;
  d.look_alike_chosen = static_cast<int>(chosen);
  d.look_alike_margin = won_by;
  if (chosen != 0 && cmp.informative) d.colour_agreement = cmp.alternatives[chosen].colour, d.colour_measured = true;
  d.look_alike_alternatives = std::move(cmp.alternatives);
  if (chosen == 0) return;
  // Verified as any pose is, from the model surface its own rendering shows; a composed
  // near-symmetry is a few millimetres off, so the fine fit runs once more from there.
  const std::size_t k = cmp.member[chosen];
  const bool is_refit = k == 1 + (chosen - 1) * family;
  replacePose(c, views[k], poses[k], window, frame, is_refit ? &refits[chosen - 1] : nullptr);
}

}  // namespace vkpose
