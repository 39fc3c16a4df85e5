// Frames without depth (colour_only.hpp): the Detector's colour-only flow and its steps.
#include "pipeline/colour_only.hpp"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <iterator>
#include <limits>
#include <numeric>
#include <optional>

#include <fmt/format.h>

#include "match/match_templates.hpp"
#include "pipeline/pipeline.hpp"
#include "pose/appearance.hpp"
#include "render/render.hpp"
#include "util/parallel.hpp"
#include "util/timing.hpp"
#include "vkpose/error.hpp"

namespace vkpose {

using util::msSince;

namespace {
/// Fewer outline points than this at the final pose: too small or too far off the image to say.
constexpr std::size_t kMinContourPoints = 30;
}  // namespace

std::vector<LinemodTemplate> colourTemplates(const std::vector<TemplateBank>& banks, std::vector<int>& global_ids) {
  std::vector<LinemodTemplate> out;
  global_ids.clear();
  int id = 0;
  for (const TemplateBank& bank : banks) {
    if (!bank.params.features.use_colour)
      throw InputError(fmt::format(
          "bank '{}' has no colour modality (trained on depth alone), so it cannot detect in a frame without depth: "
          "give the depth image, or train the bank with colour (the default)",
          bank.object));
    for (const BankTemplate& t : bank.templates) {
      if (std::optional<LinemodTemplate> c = match::colourFeaturesAlone(t.linemod)) {
        out.push_back(std::move(*c));
        global_ids.push_back(id);
      }
      ++id;
    }
  }
  if (out.empty()) throw InputError("no template of the banks has colour features: nothing to match without depth");
  return out;
}

void scoreBySimilarity(std::vector<Hypothesis>& hypotheses) {
  for (Hypothesis& h : hypotheses) {
    h.member_scores.assign(h.members.size(), MemberScore{});
    const std::size_t n = std::min<std::size_t>(3, h.members.size());
    float sum = 0.f;
    for (std::size_t k = 0; k < n; ++k) sum += h.members[k].similarity;  // best first
    h.score = n ? sum / (100.f * static_cast<float>(n)) : 0.f;
    h.alpha = h.beta = 0.f;
    h.best_member = h.members.empty() ? -1 : 0;
  }
}

namespace {

/// Each candidate's model rendered at `poses[i]` in its own window (one submit each, in the
/// calling thread: the renderers share one workspace).
std::vector<std::pair<Rendering, cv::Rect>> renderAt(const std::vector<PoseCandidate>& candidates,
                                                     const std::vector<Pose>& poses,
                                                     const std::vector<PoseObject>& objects, const Camera& camera) {
  std::vector<std::pair<Rendering, cv::Rect>> out(candidates.size());
  for (std::size_t i = 0; i < candidates.size(); ++i) {
    const PoseObject& o = objects[candidates[i].bank()];
    const cv::Rect window = projectedWindow(poses[i], o.bank->centre, o.bounding_radius, camera);
    if (window.width < 4 || window.height < 4) continue;
    out[i] = {std::move(o.renderer->render(windowCamera(camera, window), {poses[i]}).front()), window};
  }
  return out;
}

/// Why a fitted pose cannot be the hypothesis's object (empty: it can): too little outline to
/// have fitted, a distance outside the bank's trained radii (the fit slid along the ray,
/// where the outline says least), or a centre that left the hypothesis's place.
std::string implausibleFit(const PoseCandidate& c, const Pose& pose, const TemplateBank& bank, const Camera& camera,
                           std::size_t points) {
  if (points < kMinContourPoints)
    return fmt::format("{} points of outline, too few to fit ({} needed)", points, kMinContourPoints);
  const Eigen::Vector3f centre = pose.R * bank.centre + pose.t;
  const float near = 0.75f * bank.params.views.radii.from, far = 1.33f * bank.params.views.radii.to;
  if (!(centre.z() >= near && centre.z() <= far))
    return fmt::format("the fit moved it to {:.2f} m, outside the trained distances ({:.2f}-{:.2f} m)", centre.z(),
                       bank.params.views.radii.from, bank.params.views.radii.to);
  const Eigen::Vector2f at = camera.project(centre);
  const float diameter_px = camera.pixelsAcross(bank.diameter, centre.z());
  if ((at - Eigen::Vector2f(c.detection.x, c.detection.y)).norm() > 0.5f * diameter_px)
    return "the fit slid off its hypothesis's place";
  return {};
}

/// The colour agreement of a rendering with the frame over its mask (appearanceAgreement with
/// the rendering's own depth standing in for the scene's: every rendered pixel counts).
AppearanceAgreement colourAgreement(const Rendering& rendering, const cv::Rect& window, const cv::Mat& bgr) {
  const cv::Mat seen = bgr(window).clone();
  return appearanceAgreement(rendering, cv::Rect(0, 0, window.width, window.height), seen, rendering.depth, 1.f, true);
}

}  // namespace

void fitAndVerifyByContour(std::vector<PoseCandidate>& candidates, const std::vector<PoseObject>& objects,
                           const Camera& camera, const cv::Mat& bgr, const EdgeDistanceMaps& maps,
                           const DetectorParams& params, const ContourFitParams& fit_params) {
  const ColourOnlyParams& cp = params.colour_only;
  const std::size_t n = candidates.size();
  std::vector<Pose> poses(n);
  for (std::size_t i = 0; i < n; ++i) poses[i] = candidates[i].start;
  std::vector<char> lost(n, 0);
  for (const float truncation : fit_params.truncation_px) {
    auto rendered = renderAt(candidates, poses, objects, camera);
    util::parallelFor(
        n,
        [&](std::size_t i) {
          if (lost[i]) return;
          const auto start = std::chrono::steady_clock::now();
          const auto& [rendering, window] = rendered[i];
          if (window.empty()) {
            lost[i] = 1;
            return;
          }
          // A mesh without colours is fitted by its outline alone: the edges of its shading
          // pulled fits started at the truth 4-28 degrees off (the milk jug on the synthetic
          // tables). Verification below keeps them but over a surface of one colour: without
          // them a box-like outline passes on any box.
          const bool own_colours = !objects[candidates[i].bank()].bank->mesh.colours.empty();
          const auto points = contourPoints(rendering, poses[i], camera, window, 400, 0.01f, own_colours);
          const ContourFit fit =
              fitContourRound(points, poses[i], camera, maps, truncation, fit_params.iterations);
          poses[i] = fit.pose;
          candidates[i].detection.icp_iterations += fit.iterations;
          candidates[i].cpu_ms += msSince(start);
        },
        params.threads);
  }
  // Verification at the final pose.
  auto rendered = renderAt(candidates, poses, objects, camera);
  util::parallelFor(
      n,
      [&](std::size_t i) {
        PoseCandidate& c = candidates[i];
        Detection& d = c.detection;
        d.pose = poses[i];
        d.colour_only = true;
        const auto& [rendering, window] = rendered[i];
        if (lost[i] || window.empty()) {
          d.rejection = "the model renders outside the image";
          d.score = 0.f;
          return;
        }
        const auto points = contourPoints(rendering, poses[i], camera, window);
        if (const std::string why = implausibleFit(c, poses[i], *objects[c.bank()].bank, camera, points.size());
            !why.empty()) {
          d.rejection = why;
          d.score = 0.f;
          return;
        }
        const bool own_colours = !objects[c.bank()].bank->mesh.colours.empty();
        // Over a surface of one colour a mesh without colours is verified by its outline alone,
        // asking more of it: the frame's light need not put edges where the rendered shading has them.
        // Over several colours it is held to more of every edge (min_uncoloured_mixed_support):
        // a right pose shows the part's one colour, a wrong one lies mostly on another object.
        const float spread = own_colours ? std::numeric_limits<float>::quiet_NaN()
                                         : seenChromaSpread(rendering, window, bgr);
        const bool plain = cp.min_plain_outline_support > 0.f && spread < kMinChromaSpread;
        const bool mixed =
            spread >= kMinChromaSpread && cp.min_uncoloured_mixed_support > cp.min_contour_support;
        d.contour_edges = chamferSupport(points, poses[i], camera, maps, cp.edge_tolerance_px);
        // The outline alone gates; the score keeps every edge, so that a plain mesh's pose
        // does not outrank another object's for having fewer edges to explain.
        d.plain_outline_edges =
            plain ? chamferSupport(contourPoints(rendering, poses[i], camera, window, 400, 0.01f, false), poses[i],
                                   camera, maps, cp.edge_tolerance_px)
                  : std::numeric_limits<float>::quiet_NaN();
        const float tested = plain ? d.plain_outline_edges : d.contour_edges;
        const float needed = plain   ? cp.min_plain_outline_support
                             : mixed ? cp.min_uncoloured_mixed_support
                                     : cp.min_contour_support;
        c.outline_passed = !(tested < needed);
        const AppearanceAgreement colour = colourAgreement(rendering, window, bgr);
        const bool colour_counts = own_colours && colour.colour_informative;
        d.colour_agreement = colour_counts ? colour.colour : 1.f;
        d.colour_measured = colour_counts;
        d.explained_edges = explainedEdgeShare(rendering, window, maps, cp.edge_tolerance_px);
        d.score = d.contour_edges * d.explained_edges * (colour_counts ? 0.5f * (1.f + colour.colour) : 1.f);
        // The outline and the edges barely tell a pose 6-14 px off from the right one; the
        // right one separates its object's colours from the surroundings' best.
        if (cp.region_contrast_power > 0.f) {
          d.region_contrast = regionContrast(rendering, window, bgr);
          d.score *= std::pow(std::max(d.region_contrast, 0.f), cp.region_contrast_power);
        }
        if (!c.outline_passed)
          d.rejection = fmt::format("{:.0f} % of its {} meets an image edge, {:.0f} % needed{}", 100.f * tested,
                                    plain ? "outline alone" : "outline", 100.f * needed,
                                    mixed ? " (a mesh without colours over several colours)" : "");
        else if (const float agreement = objects[c.bank()].colourful ? cp.min_colourful_agreement : cp.min_colour_agreement;
                 colour_counts && agreement > -1.f && colour.colour < agreement)
          d.rejection = fmt::format("its colours agree {:.2f} with the frame's, {:.2f} needed", colour.colour, agreement);
        d.verified = d.rejection.empty();
      },
      params.threads);
}

/// Of each hypothesis's starts the best scored; the others that had passed go to the rejected
/// (those that had not are dropped: their hypothesis is represented by the best). Returns, per
/// candidate kept, whether it was one of those from `first_restart` on (a restart that won).
static std::vector<char> keepBestStart(std::vector<PoseCandidate>& candidates,
                                       const std::vector<std::size_t>& hypothesis_of, DetectionResult& result,
                                       std::size_t first_restart) {
  std::vector<int> best(candidates.size(), -1);
  for (std::size_t i = 0; i < candidates.size(); ++i) {
    int& b = best[hypothesis_of[i]];
    if (b < 0 || candidates[i].detection.score > candidates[static_cast<std::size_t>(b)].detection.score)
      b = static_cast<int>(i);
  }
  std::vector<PoseCandidate> kept;
  std::vector<char> restarted;
  for (std::size_t i = 0; i < candidates.size(); ++i) {
    if (best[hypothesis_of[i]] == static_cast<int>(i)) {
      kept.push_back(std::move(candidates[i]));
      restarted.push_back(i >= first_restart ? 1 : 0);
    } else if (candidates[i].detection.verified) {
      candidates[i].detection.verified = false;
      candidates[i].detection.rejection = "another rotation start of its hypothesis fit better";
      result.rejected.push_back(std::move(candidates[i].detection));
    }
  }
  candidates = std::move(kept);
  return restarted;
}

/// The turns of a pose that its templates cannot tell from it: the bank's near-symmetries where
/// the mesh's colours can (a painted carton turned a quarter about its axis has the same
/// outline), and the look-alike half-turns (a carton end for end). None for a symmetric bank.
static std::vector<Pose> lookAlikeTurns(const PoseObject& object) {
  std::vector<Pose> turns;
  if (object.bank->symmetric) return turns;
  if (object.colourful)
    for (const NearSymmetry& s : object.bank->near_symmetries) turns.push_back(s.transform());
  for (const NearSymmetry& s : object.look_alike_turns) turns.push_back(s.transform());
  return turns;
}

std::vector<Pose> colourOnlyRestarts(const Pose& pose, const PoseObject& object, const ColourOnlyParams& cp) {
  std::vector<Pose> out;
  if (cp.try_turns)
    for (const Pose& turn : lookAlikeTurns(object)) out.push_back(compose(pose, turn));
  if (cp.tilt_restart_deg > 0.f) {
    const float angle = cp.tilt_restart_deg * static_cast<float>(M_PI / 180.0);
    const Eigen::Vector3f centre = pose.R * object.bank->centre + pose.t;
    for (const int axis : {0, 1})  // the camera's x and y
      for (const float sign : {1.f, -1.f}) {
        const Eigen::Matrix3f Q = Eigen::AngleAxisf(sign * angle, Eigen::Vector3f::Unit(axis)).toRotationMatrix();
        out.push_back({Q * pose.R, Q * (pose.t - centre) + centre});
      }
  }
  return out;
}

namespace {

/// Whether a fitted candidate is worth restarting: it scored and its outline passed.
bool outlinePassed(const PoseCandidate& c) { return c.detection.score > 0.f && c.outline_passed; }

/// `c` to be fitted again from `start`: its verdict and CPU time cleared.
PoseCandidate restartAt(PoseCandidate c, const Pose& start) {
  c.start = start;
  c.detection.rejection.clear();
  c.detection.verified = false;
  c.outline_passed = false;
  c.cpu_ms = 0;
  return c;
}

/// The fits of `candidates` counted in the result (refined_candidates, refine_cpu_ms).
void countFits(const std::vector<PoseCandidate>& candidates, DetectionResult& result) {
  for (const PoseCandidate& c : candidates) ++result.refined_candidates, result.refine_cpu_ms += c.cpu_ms;
}

}  // namespace

std::vector<Eigen::Matrix3f> colourTurns() {
  std::vector<Eigen::Matrix3f> turns;
  // The turns of a cube: the axes permuted, with the signs that keep the determinant +1.
  std::array<int, 3> axes{0, 1, 2};
  do {
    for (int signs = 0; signs < 8; ++signs) {
      Eigen::Matrix3f Q = Eigen::Matrix3f::Zero();
      for (int r = 0; r < 3; ++r) Q(r, axes[static_cast<std::size_t>(r)]) = (signs >> r & 1) ? -1.f : 1.f;
      if (Q.determinant() > 0.f && !Q.isIdentity()) turns.push_back(Q);
    }
  } while (std::next_permutation(axes.begin(), axes.end()));
  for (const int axis : {0, 1, 2})
    for (const float deg : {45.f, 135.f, 225.f, 315.f})
      turns.push_back(
          Eigen::AngleAxisf(deg * static_cast<float>(M_PI / 180.0), Eigen::Vector3f::Unit(axis)).toRotationMatrix());
  return turns;
}

/// For each candidate of a colourful object whose outline passed, its pose turned through the
/// model's centre by each of colourTurns(), fitted one round and scored; the
/// ColourOnlyParams::colour_turns best of each are appended to `again` as starts (`of`: the
/// candidate each came from).
static void addColourTurnStarts(const std::vector<PoseCandidate>& candidates, const std::vector<PoseObject>& objects,
                                const Camera& camera, const cv::Mat& bgr, const EdgeDistanceMaps& maps,
                                const DetectorParams& params, DetectionResult& result,
                                std::vector<PoseCandidate>& again, std::vector<std::size_t>& of) {
  const ColourOnlyParams& cp = params.colour_only;
  if (cp.colour_turns <= 0) return;
  const std::vector<Eigen::Matrix3f> turns = colourTurns();
  std::vector<PoseCandidate> screened;
  std::vector<std::size_t> screened_of;
  for (std::size_t i = 0; i < candidates.size(); ++i) {
    const Detection& d = candidates[i].detection;
    const PoseObject& object = objects[candidates[i].bank()];
    if (!outlinePassed(candidates[i]) || !object.colourful || object.bank->symmetric) continue;
    const Eigen::Vector3f centre = object.bank->centre;
    for (const Eigen::Matrix3f& Q : turns) {
      screened.push_back(restartAt(candidates[i], compose(d.pose, Pose{Q, centre - Q * centre})));
      screened_of.push_back(i);
    }
  }
  if (screened.empty()) return;
  ContourFitParams one_round;
  one_round.truncation_px = {10.f};
  fitAndVerifyByContour(screened, objects, camera, bgr, maps, params, one_round);
  countFits(screened, result);
  std::vector<std::vector<std::size_t>> of_candidate(candidates.size());
  for (std::size_t k = 0; k < screened.size(); ++k) of_candidate[screened_of[k]].push_back(k);
  for (std::size_t i = 0; i < candidates.size(); ++i) {
    std::vector<std::size_t>& ks = of_candidate[i];
    std::stable_sort(ks.begin(), ks.end(), [&](std::size_t a, std::size_t b) {
      return screened[a].detection.score > screened[b].detection.score;
    });
    for (std::size_t r = 0; r < std::min(ks.size(), static_cast<std::size_t>(cp.colour_turns)); ++r) {
      PoseCandidate& c = screened[ks[r]];
      if (!(c.detection.score > 0.f)) break;
      const Pose reached = c.detection.pose;  // on from where the screening round left it
      again.push_back(restartAt(std::move(c), reached));
      of.push_back(i);
    }
  }
}

/// One round of refitFromRestarts. `improved`: null in the first round (every candidate whose
/// outline passed, the colour turns too); then which candidates a restart improved in the
/// round before (their look-alike turns and tilts only). Returns, per candidate kept, whether
/// a restart won.
static std::vector<char> restartRound(std::vector<PoseCandidate>& candidates, const std::vector<PoseObject>& objects,
                                      const Camera& camera, const cv::Mat& bgr, const EdgeDistanceMaps& maps,
                                      const DetectorParams& params, DetectionResult& result,
                                      const std::vector<char>* improved) {
  const ColourOnlyParams& cp = params.colour_only;
  std::vector<PoseCandidate> again;
  std::vector<std::size_t> of(candidates.size());
  std::iota(of.begin(), of.end(), std::size_t{0});
  for (std::size_t i = 0; i < candidates.size(); ++i) {
    const Detection& d = candidates[i].detection;
    if (!outlinePassed(candidates[i]) || (improved && !(*improved)[i])) continue;
    for (const Pose& start : colourOnlyRestarts(d.pose, objects[candidates[i].bank()], cp)) {
      again.push_back(restartAt(candidates[i], start));
      of.push_back(i);
    }
  }
  if (!improved) addColourTurnStarts(candidates, objects, camera, bgr, maps, params, result, again, of);
  if (again.empty()) return std::vector<char>(candidates.size(), 0);
  ContourFitParams finer;
  finer.truncation_px = {10.f, 5.f, 3.f};
  fitAndVerifyByContour(again, objects, camera, bgr, maps, params, finer);
  countFits(again, result);
  const std::size_t first_restart = candidates.size();
  std::move(again.begin(), again.end(), std::back_inserter(candidates));
  return keepBestStart(candidates, of, result, first_restart);
}

void refitFromRestarts(std::vector<PoseCandidate>& candidates, const std::vector<PoseObject>& objects,
                       const Camera& camera, const cv::Mat& bgr, const EdgeDistanceMaps& maps,
                       const DetectorParams& params, DetectionResult& result) {
  std::vector<char> improved = restartRound(candidates, objects, camera, bgr, maps, params, result, nullptr);
  for (int round = 1; round < params.colour_only.restart_rounds; ++round) {
    if (std::find(improved.begin(), improved.end(), 1) == improved.end()) break;
    improved = restartRound(candidates, objects, camera, bgr, maps, params, result, &improved);
  }
}

/// The accepted candidates, best score first, each unless a better one's centre projects
/// within half the smaller projected diameter of its own (one place holds one object: without
/// depth, two objects cannot be told apart along a ray).
static void acceptByContour(std::vector<PoseCandidate>& candidates, const std::vector<TemplateBank>& banks,
                            const Camera& camera, DetectionResult& result) {
  std::stable_sort(candidates.begin(), candidates.end(), [](const PoseCandidate& a, const PoseCandidate& b) {
    return a.detection.score > b.detection.score;
  });
  struct Place {
    Eigen::Vector2f at;
    float radius;
  };
  std::vector<Place> taken;
  for (PoseCandidate& c : candidates) {
    Detection& d = c.detection;
    if (!d.verified) {
      result.rejected.push_back(std::move(d));
      continue;
    }
    const TemplateBank& bank = banks[c.bank()];
    const Eigen::Vector3f centre = d.pose.R * bank.centre + d.pose.t;
    const Place place{camera.project(centre), camera.pixelsAcross(0.5f * bank.diameter, centre.z())};
    const bool duplicate = std::any_of(taken.begin(), taken.end(), [&](const Place& p) {
      return (p.at - place.at).norm() < std::min(p.radius, place.radius);
    });
    if (duplicate) {
      d.verified = false;
      d.rejection = "a better detection holds its place";
      result.rejected.push_back(std::move(d));
      continue;
    }
    taken.push_back(place);
    d.x = place.at.x();
    d.y = place.at.y();
    result.detections.push_back(std::move(d));
  }
}

DetectionResult Detector::detectColourOnly(const LinemodFrame& frame, const Camera& frame_camera) {
  FeatureParams features = banks_.front().params.features;
  features.use_depth = false;
  const Camera camera = frameCamera(frame, frame_camera, features);
  if (!colour_only_) {
    auto stages = std::make_unique<ColourOnlyStages>();
    std::vector<LinemodTemplate> templates = colourTemplates(banks_, stages->global_ids);
    MatchParams match = params_.match;
    match.threshold = params_.colour_only.threshold;
    stages->matcher = std::make_unique<LinemodMatcher>(ctx_, features, match);
    stages->matcher->setTemplates(std::move(templates));
    colour_only_ = std::move(stages);
  }
  DetectionResult result;
  result.warnings = focalLengthWarnings(banks_, camera);
  const auto total0 = std::chrono::steady_clock::now();
  std::vector<Match> matches = colour_only_->matcher->match(frame);
  for (Match& m : matches) m.template_id = colour_only_->global_ids[static_cast<std::size_t>(m.template_id)];
  appendMatchTimings(colour_only_->matcher->lastTimings(), result);
  result.matches = matches.size();

  StageClock clock(ctx_);
  std::vector<Hypothesis> hypotheses = clusterTemplates(matches, banks_, params_.cluster);
  result.hypotheses = hypotheses.size();
  clock.end(Stage::clustering, result);
  scoreBySimilarity(hypotheses);
  result.scored_hypotheses = hypotheses.size();
  clock.end(Stage::scoring, result);

  NmsParams nms = params_.nms;
  nms.across_objects = !params_.estimate_poses;
  nms.small_part_radius_fraction = nms.radius_fraction;
  hypotheses = suppressNonMaxima(std::move(hypotheses), banks_, camera.fx, nms);
  std::vector<int> taken(banks_.size(), 0);
  std::erase_if(hypotheses, [&](const Hypothesis& h) {
    return taken[static_cast<std::size_t>(h.bank)]++ >= params_.colour_only.candidates_per_object;
  });
  clock.end(Stage::nms, result);
  if (!params_.estimate_poses) {
    result.detections = templateDetections(hypotheses, banks_, camera);
    addStage(result.timings_ms, Stage::total, msSince(total0));
    return result;
  }

  const auto wall0 = std::chrono::steady_clock::now();
  const double cpu0 = util::processCpuMs();
  // Several rotation starts a hypothesis (the largest groups of its templates' rotations):
  // without depth a cluster mixes views whose outlines look alike more often, and the fit
  // cannot turn far. The best-supported start of each hypothesis is kept. (No start by fit:
  // scoreBySimilarity leaves the members without a depth fit. The best match's group instead:
  // a jug lying in plain sight, its cluster's best template 5-8 degrees from the truth, had six
  // larger groups of its other side.)
  std::vector<PoseCandidate> candidates;
  std::vector<std::size_t> hypothesis_of;
  for (std::size_t k = 0; k < hypotheses.size(); ++k)
    for (PoseCandidate& c : hypothesisStarts(hypotheses[k], banks_, camera, params_, params_.colour_only.starts, true)) {
      candidates.push_back(std::move(c));
      hypothesis_of.push_back(k);
    }
  attachRenderers();
  clock.end(Stage::initial_pose, result);
  const EdgeDistanceMaps maps = edgeDistanceMaps(frame.bgr, params_.colour_only.canny_low, params_.colour_only.canny_high);
  clock.end(Stage::edges, result);
  fitAndVerifyByContour(candidates, objects_, camera, frame.bgr, maps, params_);
  countFits(candidates, result);
  keepBestStart(candidates, hypothesis_of, result, candidates.size());
  refitFromRestarts(candidates, objects_, camera, frame.bgr, maps, params_, result);
  clock.end(Stage::contour_fit, result);
  acceptByContour(candidates, banks_, camera, result);
  clock.end(Stage::verification, result);
  result.pose_wall_ms = msSince(wall0);
  result.pose_cpu_ms = util::processCpuMs() - cpu0;
  result.pose_threads = util::threadsFor(candidates.size(), params_.threads);
  addStage(result.timings_ms, Stage::total, msSince(total0));
  return result;
}

}  // namespace vkpose
