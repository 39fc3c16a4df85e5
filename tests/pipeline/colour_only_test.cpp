// Colour-only detection (docs/pipeline.md, frames without depth): the directional chamfer fit of
// stage 7 on a rendered scene, the 2D projection metric, and the detector on the real LM-O frame
// with its depth withheld.
#include <algorithm>
#include <cmath>
#include <map>
#include <set>
#include <tuple>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "mesh_support.hpp"
#include "pipeline/colour_only.hpp"
#include "pose/appearance.hpp"
#include "pose/contour_fit.hpp"
#include "pose/initial_pose.hpp"
#include "render/render.hpp"
#include "test_support.hpp"
#include "vkpose/error.hpp"
#include "vkpose/evaluation.hpp"

namespace vkpose {
namespace {

TEST(ContourFit, OrientationBinsIgnoreTheSign) {
  EXPECT_EQ(edgeOrientationBin(1, 0), 0);
  EXPECT_EQ(edgeOrientationBin(-1, 0), 0);
  EXPECT_EQ(edgeOrientationBin(1, 1), 2);
  EXPECT_EQ(edgeOrientationBin(0, 1), 4);
  EXPECT_EQ(edgeOrientationBin(0, -1), 4);
  EXPECT_EQ(edgeOrientationBin(-1, 1), 6);
  EXPECT_EQ(edgeOrientationBin(1, -1), 6);
}

struct Scene {
  Mesh mesh = test::lShapeMesh();
  Camera camera;
  Pose truth;
  cv::Mat bgr;

  /// The image window the L-shape at `pose` covers (its farthest vertex from the origin).
  cv::Rect windowAt(const Pose& pose) const {
    float radius = 0.f;
    for (const auto& v : mesh.vertices) radius = std::max(radius, v.norm());
    return projectedWindow(pose, Eigen::Vector3f::Zero(), radius, camera);
  }
};

/// The L-shape rendered (the reference rasterizer, shaded grey) on an orange background (a
/// grey one would hide the outline wherever a face is shaded the same grey).
Scene renderedScene() {
  Scene s;
  s.truth.R = (Eigen::AngleAxisf(0.5f, Eigen::Vector3f::UnitX()) * Eigen::AngleAxisf(0.3f, Eigen::Vector3f::UnitY()))
                  .toRotationMatrix();
  s.truth.t = {0.03f, -0.02f, 0.6f};
  const Rendering r = renderReference(s.mesh, s.camera, s.truth);
  s.bgr = cv::Mat(s.camera.height, s.camera.width, CV_8UC3, cv::Scalar(20, 90, 200));
  r.bgr.copyTo(s.bgr, r.mask());
  return s;
}

/// proj2d of the mesh's vertices between two poses, pixels.
float proj2d(const Scene& s, const Pose& p) {
  return proj2dError(s.mesh.vertices, p.R, p.t, s.truth.R, s.truth.t, s.camera);
}

/// Rounds of render, outline and fit from `start`, as the detector runs them.
Pose fitFrom(const Scene& s, const EdgeDistanceMaps& maps, Pose pose) {
  for (const float truncation : ContourFitParams{}.truncation_px) {
    const cv::Rect window = s.windowAt(pose);
    const Rendering r = renderReference(s.mesh, windowCamera(s.camera, window), pose);
    const auto points = contourPoints(r, pose, s.camera, window);
    EXPECT_GT(points.size(), 50u);
    pose = fitContourRound(points, pose, s.camera, maps, truncation, ContourFitParams{}.iterations).pose;
  }
  return pose;
}

TEST(ContourFit, PullsAShiftedAndTurnedPoseBackOntoTheEdges) {
  const Scene s = renderedScene();
  const EdgeDistanceMaps maps = edgeDistanceMaps(s.bgr);
  Pose start = s.truth;
  start.R = Eigen::AngleAxisf(0.08f, Eigen::Vector3f(0.3f, 1.f, 0.2f).normalized()).toRotationMatrix() * s.truth.R;
  start.t += Eigen::Vector3f(0.006f, 0.004f, 0.02f);  // about 6 and 4 px, and 2 cm farther
  ASSERT_GT(proj2d(s, start), 6.f);
  const Pose fitted = fitFrom(s, maps, start);
  EXPECT_LT(proj2d(s, fitted), 1.5f) << "from " << proj2d(s, start) << " px";
}

TEST(ContourFit, SupportIsHighOnTheObjectAndLowBesideIt) {
  const Scene s = renderedScene();
  const EdgeDistanceMaps maps = edgeDistanceMaps(s.bgr);
  const cv::Rect window = s.windowAt(s.truth);
  const auto points =
      contourPoints(renderReference(s.mesh, windowCamera(s.camera, window), s.truth), s.truth, s.camera, window);
  EXPECT_GT(chamferSupport(points, s.truth, s.camera, maps), 0.9f);
  Pose beside = s.truth;
  beside.t.x() += 0.012f;  // about 11 px
  EXPECT_LT(chamferSupport(points, beside, s.camera, maps), 0.4f);
}

TEST(ContourFit, WithoutColourEdgesTheShadedInsideIsLeftOut) {
  // The L-shape has no colours: its rendering is shaded, and the shading changes across its
  // folds inside the outline. Without colour edges those inner points go; the outline and the
  // depth steps stay, point for point.
  const Scene s = renderedScene();
  const cv::Rect window = s.windowAt(s.truth);
  const Rendering r = renderReference(s.mesh, windowCamera(s.camera, window), s.truth);
  constexpr int kAll = 1 << 20;  // no thinning: the two sets can be compared point for point
  const auto with = contourPoints(r, s.truth, s.camera, window, kAll, 0.01f, true);
  const auto without = contourPoints(r, s.truth, s.camera, window, kAll, 0.01f, false);
  using PointKey = std::tuple<float, float, float, uint8_t>;
  const auto key = [](const ContourPoint& p) { return PointKey(p.model.x(), p.model.y(), p.model.z(), p.bin); };
  std::set<PointKey> kept;
  for (const ContourPoint& p : with) kept.insert(key(p));
  ASSERT_GT(without.size(), 50u);
  for (const ContourPoint& p : without) EXPECT_TRUE(kept.count(key(p))) << "a point that colour edges do not add";
  EXPECT_GT(with.size(), without.size() + 20) << "the shaded L-shape shows no edge inside its outline";
  // What went is inside: two pixels or more in from the mask's border.
  cv::Mat inner;
  cv::erode(r.mask(), inner, cv::Mat(), {-1, -1}, 2);
  std::set<PointKey> outline;
  for (const ContourPoint& p : without) outline.insert(key(p));
  for (const ContourPoint& p : with) {
    if (outline.count(key(p))) continue;
    const Eigen::Vector2f uv = s.camera.project(s.truth.R * p.model + s.truth.t);
    const int x = static_cast<int>(std::lround(uv.x())) - window.x, y = static_cast<int>(std::lround(uv.y())) - window.y;
    ASSERT_TRUE(x >= 0 && y >= 0 && x < inner.cols && y < inner.rows);
    EXPECT_TRUE(inner.at<uint8_t>(y, x)) << "a colour edge point on the outline at " << x << "," << y;
  }
}

TEST(Proj2d, IsZeroForThePoseItselfAndTheShiftInPixels) {
  const Camera camera;
  const std::vector<Eigen::Vector3f> points{{0.f, 0.f, 0.f}, {0.05f, 0.f, 0.f}, {0.f, 0.05f, 0.02f}};
  const Eigen::Matrix3f R = Eigen::Matrix3f::Identity();
  const Eigen::Vector3f t(0.f, 0.f, 1.f);
  EXPECT_FLOAT_EQ(proj2dError(points, R, t, R, t, camera), 0.f);
  // 1 cm sideways at 1 m: fx * 0.01 px for the points at z = 1, a little less for the far one.
  const float e = proj2dError(points, R, t + Eigen::Vector3f(0.01f, 0.f, 0.f), R, t, camera);
  EXPECT_NEAR(e, static_cast<float>(camera.fx) * 0.01f, 0.1f);
  EXPECT_LT(e, static_cast<float>(camera.fx) * 0.01f);
}

TEST(Proj2d, ASymmetricObjectTurnedAboutItsAxisIsNotWrong) {
  // A ring of points about z: turned 30 degrees about z it projects onto itself, which ADD's
  // rule counts as tens of pixels off and ADI's as none.
  std::vector<Eigen::Vector3f> ring;
  for (int k = 0; k < 360; ++k)
    ring.emplace_back(0.05f * std::cos(k * 0.0174533f), 0.05f * std::sin(k * 0.0174533f), 0.f);
  std::map<int, EvalModel> models;
  ModelInfo info;
  info.diameter = 0.1f;
  info.symmetric = true;
  models.emplace(1, makeEvalModel(info, ring));
  const Camera camera;
  GroundTruthPose gt;
  gt.obj_id = 1;
  gt.t = {0.f, 0.f, 0.8f};
  PoseEstimate turned{1, 1.f, Eigen::AngleAxisf(0.5236f, Eigen::Vector3f::UnitZ()).toRotationMatrix(), gt.t};
  EXPECT_LT(poseError(models.at(1), turned, gt, PoseErrorType::Proj2D, &camera), 0.2f);
  models.at(1).info.symmetric = false;
  EXPECT_GT(poseError(models.at(1), turned, gt, PoseErrorType::Proj2D, &camera), 10.f);
  EXPECT_ANY_THROW((void)poseError(models.at(1), turned, gt, PoseErrorType::Proj2D, nullptr));
}

TEST(ColourOnly, ABankWithoutTheColourModalityIsAClearError) {
  TemplateBank bank;
  bank.object = "depth_only";
  bank.params.features.use_colour = false;
  std::vector<int> ids;
  test::expectInputError([&] { (void)colourTemplates({bank}, ids); }, {"depth_only", "colour"});
}

/// A box of square section (a quarter-turn about its long axis fits the outline) whose corners
/// are painted four ways around that axis, so colour tells the turns apart.
struct PaintedBoxScene {
  Mesh mesh = test::boxMesh({0.08f, 0.08f, 0.16f});
  TemplateBank bank;
  Camera camera;
  Pose truth;
  cv::Mat bgr;
  PaintedBoxScene() {
    for (const auto& v : mesh.vertices)
      mesh.colours.emplace_back(v.x() > 0.f ? 0.9f : 0.1f, v.y() > 0.f ? 0.8f : 0.15f, 0.3f);
    bank.object = "painted_box";
    bank.mesh = mesh;
    bank.diameter = mesh.diameter;
    bank.params.views.radii = {0.5f, 0.8f, 0.1f};
    bank.near_symmetries = findNearSymmetries(mesh, 0.01f * mesh.diameter);
    truth.R = (Eigen::AngleAxisf(1.1f, Eigen::Vector3f::UnitX()) * Eigen::AngleAxisf(0.5f, Eigen::Vector3f::UnitZ()))
                  .toRotationMatrix();
    truth.t = {0.02f, -0.01f, 0.6f};
  }
  /// The bank's near-symmetry a quarter turn about the box's axis (null if it found none).
  const NearSymmetry* quarterTurn() const {
    const auto q = std::find_if(bank.near_symmetries.begin(), bank.near_symmetries.end(),
                                [](const NearSymmetry& n) { return std::abs(n.angle_deg - 90.f) < 1.f; });
    return q == bank.near_symmetries.end() ? nullptr : &*q;
  }
  /// A hypothesis at the box's place, stage 6 having started it at `start`.
  PoseCandidate candidateFrom(const Pose& start) const {
    PoseCandidate c;
    c.detection.bank = 0;
    c.detection.object = bank.object;
    c.start = start;
    const Eigen::Vector2f at = camera.project(truth.t);
    c.detection.x = at.x(), c.detection.y = at.y();
    return c;
  }
};

/// The painted box as the detector sees it (rendered by `renderer`) and the frame it is seen in:
/// the box at the truth on grey.
PoseObject paintedBoxSeen(PaintedBoxScene& s, MeshRenderer& renderer) {
  PoseObject object;
  object.bank = &s.bank;
  object.renderer = &renderer;
  object.bounding_radius = 0.5f * s.mesh.diameter;
  object.colourful = true;
  const Rendering seen = renderer.render(s.camera, {s.truth}).front();
  s.bgr = cv::Mat(s.camera.height, s.camera.width, CV_8UC3, cv::Scalar(128, 128, 128));
  seen.bgr.copyTo(s.bgr, seen.mask());
  return object;
}

TEST(ColourOnly, RestartsAreTheLookAlikeTurnsThenTiltsAboutTheCentre) {
  PaintedBoxScene s;
  ASSERT_GE(s.bank.near_symmetries.size(), 3u);  // 90, 180 and 270 degrees about z
  PoseObject object;
  object.bank = &s.bank;
  object.colourful = meshChromaSpread(s.mesh) >= kMinChromaSpread;
  ASSERT_TRUE(object.colourful);
  ColourOnlyParams cp;
  cp.tilt_restart_deg = 0.f;
  const auto turns = colourOnlyRestarts(s.truth, object, cp);
  ASSERT_EQ(turns.size(), s.bank.near_symmetries.size());
  for (std::size_t k = 0; k < turns.size(); ++k)
    EXPECT_LT((turns[k].R - s.truth.R * s.bank.near_symmetries[k].transform().R).norm(), 1e-5f);
  // A mesh whose colours cannot tell the turns apart, or a symmetric bank: no turns.
  object.colourful = false;
  EXPECT_TRUE(colourOnlyRestarts(s.truth, object, cp).empty());
  object.colourful = true;
  s.bank.symmetric = true;
  EXPECT_TRUE(colourOnlyRestarts(s.truth, object, cp).empty());
  // Tilts: four, each the given angle, about an axis in the image plane, the centre kept.
  cp.tilt_restart_deg = 20.f;
  const auto tilts = colourOnlyRestarts(s.truth, object, cp);
  ASSERT_EQ(tilts.size(), 4u);
  for (const Pose& p : tilts) {
    const Eigen::AngleAxisf turn(p.R * s.truth.R.transpose());
    EXPECT_NEAR(turn.angle(), 20.f * static_cast<float>(M_PI / 180.0), 1e-4f);
    EXPECT_NEAR(turn.axis().z(), 0.f, 1e-4f);
    EXPECT_LT((p.t - s.truth.t).norm(), 1e-5f);  // the box's centre is its origin
  }
  cp.try_turns = false;
  cp.tilt_restart_deg = 0.f;
  EXPECT_TRUE(colourOnlyRestarts(s.truth, object, cp).empty());
}

TEST(ColourOnly, AQuarterTurnThatFitsTheOutlineIsFittedAgainAndTheColoursChooseTheTruth) {
  PaintedBoxScene s;
  MeshRenderer renderer(test::context(), s.mesh);
  const PoseObject object = paintedBoxSeen(s, renderer);
  const EdgeDistanceMaps maps = edgeDistanceMaps(s.bgr);

  // Stage 6 started it a quarter-turn about the box's axis off: the outline is the same.
  const NearSymmetry* quarter = s.quarterTurn();
  ASSERT_NE(quarter, nullptr);
  const PoseCandidate c = s.candidateFrom(compose(s.truth, quarter->transform()));
  DetectorParams params;
  params.colour_only.tilt_restart_deg = 0.f;
  std::vector<PoseCandidate> candidates{c};
  fitAndVerifyByContour(candidates, {object}, s.camera, s.bgr, maps, params);
  const Detection& turned = candidates[0].detection;
  EXPECT_GT(turned.contour_edges, 0.9f);  // the outline fits ...
  EXPECT_FALSE(turned.verified);          // ... the colours do not
  EXPECT_NE(turned.rejection.find("its colours agree"), std::string::npos) << turned.rejection;

  DetectionResult result;
  refitFromRestarts(candidates, {object}, s.camera, s.bgr, maps, params, result);
  ASSERT_EQ(candidates.size(), 1u);
  const Detection& d = candidates[0].detection;
  EXPECT_TRUE(d.verified) << d.rejection;
  EXPECT_GT(d.colour_agreement, 0.8f);
  EXPECT_LT(proj2dError(s.mesh.vertices, d.pose.R, d.pose.t, s.truth.R, s.truth.t, s.camera), 1.5f);
  // Without the look-alike turns the colour turns find it (the cube's quarter turn about z is
  // one of them, screened best) ...
  params.colour_only.try_turns = false;
  std::vector<PoseCandidate> screened{c};
  fitAndVerifyByContour(screened, {object}, s.camera, s.bgr, maps, params);
  refitFromRestarts(screened, {object}, s.camera, s.bgr, maps, params, result);
  ASSERT_EQ(screened.size(), 1u);
  EXPECT_TRUE(screened[0].detection.verified) << screened[0].detection.rejection;
  EXPECT_LT(proj2dError(s.mesh.vertices, screened[0].detection.pose.R, screened[0].detection.pose.t, s.truth.R,
                        s.truth.t, s.camera),
            1.5f);
  // ... and without either it stays where it was.
  params.colour_only.colour_turns = 0;
  std::vector<PoseCandidate> alone{c};
  fitAndVerifyByContour(alone, {object}, s.camera, s.bgr, maps, params);
  refitFromRestarts(alone, {object}, s.camera, s.bgr, maps, params, result);
  EXPECT_FALSE(alone[0].detection.verified);
}

TEST(ColourOnly, APoseARestartImprovedIsRestartedAgainFromWhereItWon) {
  PaintedBoxScene s;
  MeshRenderer renderer(test::context(), s.mesh);
  const PoseObject object = paintedBoxSeen(s, renderer);
  const EdgeDistanceMaps maps = edgeDistanceMaps(s.bgr);
  const auto fitted = [&](const Pose& start, int rounds, std::size_t& fits) {
    DetectorParams params;
    params.colour_only.colour_turns = 0;
    params.colour_only.restart_rounds = rounds;
    std::vector<PoseCandidate> candidates{s.candidateFrom(start)};
    fitAndVerifyByContour(candidates, {object}, s.camera, s.bgr, maps, params);
    DetectionResult result;
    refitFromRestarts(candidates, {object}, s.camera, s.bgr, maps, params, result);
    fits = result.refined_candidates;
    return candidates.at(0).detection;
  };
  // Turned a quarter about the box's axis and tilted 29 degrees out of the image plane: after
  // one round of restarts the pose is still tens of pixels off (a restart improved it) ...
  const NearSymmetry* quarter = s.quarterTurn();
  ASSERT_NE(quarter, nullptr);
  const Eigen::Matrix3f tilt = Eigen::AngleAxisf(0.5f, Eigen::Vector3f::UnitX()).toRotationMatrix();
  const Pose turned = compose(s.truth, quarter->transform());
  const Pose start{tilt * turned.R, tilt * (turned.t - s.truth.t) + s.truth.t};
  std::size_t one_round = 0, rounds = 0;
  const Detection once = fitted(start, 1, one_round);
  const Detection more = fitted(start, 3, rounds);
  EXPECT_EQ(one_round, colourOnlyRestarts(start, object, DetectorParams{}.colour_only).size());
  EXPECT_GT(proj2dError(s.mesh.vertices, once.pose.R, once.pose.t, s.truth.R, s.truth.t, s.camera), 10.f);
  // ... restarted again from where that restart left it, it reaches the truth.
  EXPECT_GT(rounds, one_round);
  EXPECT_TRUE(more.verified) << more.rejection;
  EXPECT_LT(proj2dError(s.mesh.vertices, more.pose.R, more.pose.t, s.truth.R, s.truth.t, s.camera), 1.5f);
  EXPECT_GT(more.score, once.score);
}

/// The box of PaintedBoxScene without its colours, seen at the truth as one flat colour (a
/// plain part whose light is not the renderer's: no edge inside its outline), or its left and
/// right halves in two colours.
struct PlainBoxScene : PaintedBoxScene {
  PlainBoxScene() {
    mesh.colours.clear();
    bank.mesh = mesh;
  }
  /// The frame with the box's mask painted `left` and, right of the truth's centre, `right`.
  cv::Mat frame(MeshRenderer& renderer, const cv::Scalar& left, const cv::Scalar& right) const {
    const cv::Mat mask = renderer.render(camera, {truth}).front().mask();
    cv::Mat out(camera.height, camera.width, CV_8UC3, cv::Scalar(128, 128, 128));
    out.setTo(left, mask);
    const int middle = static_cast<int>(camera.project(truth.t).x());
    out.colRange(middle, out.cols).setTo(right, mask.colRange(middle, mask.cols));
    return out;
  }
};

TEST(ColourOnly, AMeshWithoutColoursIsVerifiedByItsOutlineOverOneColourAndByMoreEdgesOverSeveral) {
  PlainBoxScene s;
  MeshRenderer renderer(test::context(), s.mesh);
  PoseObject object;
  object.bank = &s.bank;
  object.renderer = &renderer;
  object.bounding_radius = 0.5f * s.mesh.diameter;
  const Rendering at_truth = renderer.render(s.camera, {s.truth}).front();
  const cv::Rect frame_rect(0, 0, s.camera.width, s.camera.height);
  const DetectorParams params;
  const auto verifyAtTruth = [&](const cv::Mat& bgr, const DetectorParams& p = DetectorParams{}) {
    std::vector<PoseCandidate> candidates{s.candidateFrom(s.truth)};
    fitAndVerifyByContour(candidates, {object}, s.camera, bgr, edgeDistanceMaps(bgr), p);
    return candidates[0];
  };

  // One colour: the rendered shading's edges inside (the box's folds) meet nothing, yet the
  // outline alone is all on the frame's edges, and that verifies it.
  const cv::Mat plain = s.frame(renderer, {40, 90, 200}, {40, 90, 200});
  EXPECT_LT(seenChromaSpread(at_truth, frame_rect, plain), kMinChromaSpread);
  const PoseCandidate right = verifyAtTruth(plain);
  EXPECT_TRUE(right.detection.verified) << right.detection.rejection;
  EXPECT_TRUE(right.outline_passed);
  EXPECT_GT(right.detection.plain_outline_edges, 0.9f);
  // The score keeps every edge: the unmet folds count there, so a plain part does not outrank
  // another object's pose for having fewer edges to explain.
  EXPECT_LT(right.detection.contour_edges, right.detection.plain_outline_edges - 0.1f);

  // Two colours under it: not one plain surface, so every edge counts in the test, the folds' too.
  const cv::Mat two = s.frame(renderer, {40, 90, 200}, {200, 120, 40});
  EXPECT_GT(seenChromaSpread(at_truth, frame_rect, two), kMinChromaSpread);
  const PoseCandidate split = verifyAtTruth(two);
  EXPECT_TRUE(std::isnan(split.detection.plain_outline_edges));
  EXPECT_LT(split.detection.contour_edges, right.detection.plain_outline_edges - 0.1f);
  // There a mesh without colours needs ColourOnlyParams::min_uncoloured_mixed_support of them:
  // a right pose shows the part's one colour, a pose over several is mostly on another object.
  EXPECT_LT(split.detection.contour_edges, params.colour_only.min_uncoloured_mixed_support);
  EXPECT_FALSE(split.detection.verified);
  EXPECT_NE(split.detection.rejection.find("over several colours"), std::string::npos) << split.detection.rejection;
  DetectorParams lenient;
  lenient.colour_only.min_uncoloured_mixed_support = 0.f;  // off: min_contour_support, as with colours
  const PoseCandidate split_lenient = verifyAtTruth(two, lenient);
  EXPECT_GE(split_lenient.detection.contour_edges, lenient.colour_only.min_contour_support);
  EXPECT_TRUE(split_lenient.detection.verified) << split_lenient.detection.rejection;

  // The outline asked over a plain surface is ColourOnlyParams::min_plain_outline_support: a
  // box posed on a larger plain patch (a table, the side of a bigger box) is far from its edges.
  cv::Mat patch(s.camera.height, s.camera.width, CV_8UC3, cv::Scalar(128, 128, 128));
  cv::circle(patch, {static_cast<int>(s.camera.project(s.truth.t).x()), static_cast<int>(s.camera.project(s.truth.t).y())},
             120, {40, 90, 200}, cv::FILLED);
  const PoseCandidate inside = verifyAtTruth(patch);
  EXPECT_FALSE(inside.detection.verified);
  EXPECT_FALSE(inside.outline_passed);
  EXPECT_NE(inside.detection.rejection.find("of its outline alone"), std::string::npos) << inside.detection.rejection;
  EXPECT_NE(inside.detection.rejection.find("85 % needed"), std::string::npos) << inside.detection.rejection;
}

TEST(ColourOnly, RegionContrastIsHighestWhereTheMaskSeparatesTheObjectFromItsSurroundings) {
  PlainBoxScene s;
  MeshRenderer renderer(test::context(), s.mesh);
  const cv::Rect frame_rect(0, 0, s.camera.width, s.camera.height);
  const auto renderedAt = [&](const Pose& p) { return renderer.render(s.camera, {p}).front(); };
  // The box blue on a grey table with a little noise, as a sensor gives.
  cv::Mat noise(s.camera.height, s.camera.width, CV_16SC3);
  cv::randn(noise, cv::Scalar::all(0), cv::Scalar::all(6));
  const auto noisy = [&](const cv::Mat& bgr) {
    cv::Mat wide, out;
    bgr.convertTo(wide, CV_16SC3);
    cv::Mat(wide + noise).convertTo(out, CV_8UC3);
    return out;
  };
  const cv::Mat frame = noisy(s.frame(renderer, {40, 90, 200}, {40, 90, 200}));
  const float at_truth = regionContrast(renderedAt(s.truth), frame_rect, frame);
  EXPECT_GT(at_truth, 0.9f);

  // Shifted by a third of its width, or farther away (smaller, inside the box), the mask takes
  // in table or leaves box in the band around it.
  Pose shifted = s.truth;
  shifted.t.x() += 0.03f;
  Pose farther = s.truth;
  farther.t *= 1.4f;
  EXPECT_LT(regionContrast(renderedAt(shifted), frame_rect, frame), at_truth - 0.15f);
  EXPECT_LT(regionContrast(renderedAt(farther), frame_rect, frame), at_truth - 0.15f);

  // The same colours on both sides: nothing to tell (the histograms of a few thousand noisy
  // pixels tell them apart a little by chance).
  const cv::Mat grey = noisy(cv::Mat(frame.size(), CV_8UC3, cv::Scalar(128, 128, 128)));
  EXPECT_LT(regionContrast(renderedAt(s.truth), frame_rect, grey), 0.2f);

  // Off the image: too few pixels on a side to say.
  Pose outside = s.truth;
  outside.t.x() += 2.f;
  EXPECT_EQ(regionContrast(renderedAt(outside), frame_rect, frame), 0.f);
  cv::Mat grey8;
  cv::cvtColor(frame, grey8, cv::COLOR_BGR2GRAY);
  EXPECT_THROW(regionContrast(renderedAt(s.truth), frame_rect, grey8), InputError);

  // fitAndVerifyByContour reports it and scores by it (ColourOnlyParams::region_contrast_power).
  PoseObject object;
  object.bank = &s.bank;
  object.renderer = &renderer;
  object.bounding_radius = 0.5f * s.mesh.diameter;
  const auto verified = [&](const DetectorParams& p) {
    std::vector<PoseCandidate> candidates{s.candidateFrom(s.truth)};
    fitAndVerifyByContour(candidates, {object}, s.camera, frame, edgeDistanceMaps(frame), p);
    return candidates[0].detection;
  };
  const Detection with = verified(DetectorParams{});
  DetectorParams off;
  off.colour_only.region_contrast_power = 0.f;
  const Detection without = verified(off);
  EXPECT_NEAR(with.region_contrast, at_truth, 0.05f);
  EXPECT_TRUE(std::isnan(without.region_contrast));
  EXPECT_NEAR(with.score, without.score * std::pow(with.region_contrast, DetectorParams{}.colour_only.region_contrast_power),
              1e-4f);
}

TEST(ColourOnly, TheColourTurnsAreTheCubesTurnsAndEighthTurnsEachOnce) {
  const std::vector<Eigen::Matrix3f> turns = colourTurns();
  ASSERT_EQ(turns.size(), 35u);  // 24 - 1 + 3 x 4
  for (std::size_t a = 0; a < turns.size(); ++a) {
    EXPECT_LT((turns[a] * turns[a].transpose() - Eigen::Matrix3f::Identity()).norm(), 1e-5f);
    EXPECT_NEAR(turns[a].determinant(), 1.f, 1e-5f);
    EXPECT_GT((turns[a] - Eigen::Matrix3f::Identity()).norm(), 0.5f);
    for (std::size_t b = 0; b < a; ++b) EXPECT_GT((turns[a] - turns[b]).norm(), 0.5f) << a << " " << b;
  }
  const auto has = [&](float deg, const Eigen::Vector3f& axis) {
    const Eigen::Matrix3f Q = Eigen::AngleAxisf(deg * static_cast<float>(M_PI / 180.0), axis).toRotationMatrix();
    return std::any_of(turns.begin(), turns.end(), [&](const Eigen::Matrix3f& t) { return (t - Q).norm() < 1e-4f; });
  };
  EXPECT_TRUE(has(180.f, Eigen::Vector3f::UnitX()));   // upside down
  EXPECT_TRUE(has(90.f, Eigen::Vector3f::UnitZ()));    // a quarter about the axis
  EXPECT_TRUE(has(120.f, Eigen::Vector3f(1, 1, 1).normalized()));  // corner to corner
  EXPECT_TRUE(has(45.f, Eigen::Vector3f::UnitY()));
  EXPECT_TRUE(has(315.f, Eigen::Vector3f::UnitZ()));
}

}  // namespace
}  // namespace vkpose
