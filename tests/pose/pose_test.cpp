// Stage 6 (initial pose): rotation distance and mean, clustering of template rotations against
// the group mean, the viewing-ray correction, and the centroid translation against renderings
// with a known offset, an occluder and a black hole. Stage 7's first fit: which starts go on.
#include <cmath>
#include <limits>
#include <numbers>

#include <Eigen/Geometry>
#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "hypotheses/hypotheses.hpp"
#include "match/features.hpp"
#include "match/matcher.hpp"
#include "pose/accept.hpp"
#include "pose/candidate.hpp"
#include "pose/initial_pose.hpp"
#include "render/render.hpp"
#include "synth/procedural_meshes.hpp"
#include "mesh_support.hpp"
#include "test_support.hpp"
#include "vkpose/bank.hpp"
#include "vkpose/error.hpp"
#include "vkpose/geometry.hpp"

namespace vkpose {
namespace {

constexpr float kDeg = std::numbers::pi_v<float> / 180.f;

Eigen::Matrix3f rot(float deg, const Eigen::Vector3f& axis) {
  return Eigen::AngleAxisf(deg * kDeg, axis.normalized()).toRotationMatrix();
}

TEST(InitialRotation, DistanceIsTheAxisAngleAngle) {
  const Eigen::Matrix3f a = rot(30.f, {1, 2, 3});
  EXPECT_NEAR(rotationDistance(a, a), 0.f, 1e-3f);
  EXPECT_NEAR(rotationDistance(a, a * rot(17.f, {0, 1, 0})) / kDeg, 17.f, 0.01f);
  EXPECT_NEAR(rotationDistance(Eigen::Matrix3f::Identity(), rot(180.f, {0, 0, 1})) / kDeg, 180.f, 0.01f);
}

TEST(InitialRotation, MeanAlignsQuaternionSignsAndHonoursWeights) {
  // q and -q are the same rotation: Eigen may return either from a matrix, so build the
  // inputs as quaternions of opposite sign explicitly.
  const Eigen::Quaternionf q1(rot(5.f, {0, 0, 1})), q2(rot(-5.f, {0, 0, 1}));
  Eigen::Quaternionf q2_neg;
  q2_neg.coeffs() = -q2.coeffs();
  const Eigen::Matrix3f mean = meanRotation({q1.toRotationMatrix(), q2_neg.toRotationMatrix()});
  EXPECT_NEAR(rotationDistance(mean, Eigen::Matrix3f::Identity()) / kDeg, 0.f, 0.01f);
  const Eigen::Matrix3f weighted = meanRotation({rot(0.f, {1, 0, 0}), rot(8.f, {1, 0, 0})}, {3.f, 1.f});
  EXPECT_NEAR(rotationDistance(weighted, Eigen::Matrix3f::Identity()) / kDeg, 2.f, 0.05f);
}

TEST(InitialRotation, ClustersAgainstTheGroupMeanNotItsFirstMember) {
  const Eigen::Vector3f z(0, 0, 1);
  // 0, 9 and 12 degrees: 12 is beyond 10 of the first member, but 7.5 from the mean (4.5).
  const auto groups = clusterRotations({rot(0, z), rot(9, z), rot(12, z)}, 10.f * kDeg);
  ASSERT_EQ(groups.size(), 1u);
  EXPECT_EQ(groups[0].members.size(), 3u);
  EXPECT_NEAR(rotationDistance(groups[0].mean, rot(7, z)) / kDeg, 0.f, 0.05f);
  // Two groups 60 degrees apart: the larger first, whatever the order of arrival.
  const Eigen::Vector3f x(1, 0, 0);
  const auto two = clusterRotations({rot(60, x), rot(2, z), rot(-3, z), rot(62, x), rot(1, z)}, 10.f * kDeg);
  ASSERT_EQ(two.size(), 2u);
  EXPECT_EQ(two[0].members, (std::vector<int>{1, 2, 4}));
  EXPECT_EQ(two[1].members, (std::vector<int>{0, 3}));
  // Equal sizes: the heavier group wins.
  const auto tie = clusterRotations({rot(0, z), rot(90, x)}, 10.f * kDeg, {1.f, 2.f});
  EXPECT_EQ(tie[0].members, (std::vector<int>{1}));
}

/// A bank whose templates have the given rotations (the training camera on the optical axis).
TemplateBank rotationBank(const std::vector<Eigen::Matrix3f>& rotations) {
  TemplateBank bank;
  bank.diameter = 0.1f;
  for (const auto& R : rotations) {
    BankTemplate t;
    t.pose.R = R;
    t.pose.t = {0.f, 0.f, 0.7f};
    t.distance = 0.7f;
    bank.templates.push_back(t);
  }
  return bank;
}

/// A hypothesis at the image centre at 0.7 m whose members are templates 0 .. n-1, all matched
/// there, best first (similarity `best`, then one less each).
Hypothesis centredHypothesis(const Camera& camera, int n, float best) {
  Hypothesis h;
  h.x = static_cast<float>(camera.cx);
  h.y = static_cast<float>(camera.cy);
  h.distance = 0.7f;
  for (int i = 0; i < n; ++i) h.members.push_back({i, 0, 0, best - float(i), h.x, h.y});
  h.best_member = 0;
  return h;
}

TEST(InitialRotation, TakesTheLargestGroupAndTurnsItOntoTheViewingRay) {
  const TemplateBank bank = rotationBank({rot(3, {0, 0, 1}), rot(70, {1, 0, 0}), rot(-3, {0, 0, 1}), rot(0, {0, 1, 0})});
  const Camera camera;
  for (const Eigen::Vector2f& px : {Eigen::Vector2f(float(camera.cx), float(camera.cy)), Eigen::Vector2f(5.f, 5.f)}) {
    Hypothesis h;
    h.x = px.x();
    h.y = px.y();
    h.distance = 0.7f;
    for (int i = 0; i < 4; ++i) h.members.push_back({i, 0, 0, 90.f - float(i), px.x(), px.y()});
    const InitialRotation r = initialRotation(h, bank, camera);
    EXPECT_EQ(r.group_size, 3);
    EXPECT_EQ(r.candidates, 4);
    // The mean of +3, -3 and 0 degrees is the template's frame, turned onto the ray: at the
    // top-left corner that turn is about 34 degrees.
    const Eigen::Matrix3f ray = viewingRayRotation(px.x(), px.y(), camera);
    EXPECT_LT(rotationDistance(r.R, ray) / kDeg, 0.5f);
    // The pose on the ray puts the object's centre on the ray through the hypothesis.
    const Pose p = poseOnViewingRay(r.R, h, bank, camera);
    EXPECT_LT((camera.project(p.R * bank.centre + p.t) - px).norm(), 0.01f);
    EXPECT_NEAR((p.R * bank.centre + p.t).norm(), 0.7f, 1e-4f);
  }
}

// A cluster that mixes look-alike views: the largest rotation group (three templates) fits the
// scene's depth worse than a group of two, which becomes a second start.
TEST(InitialRotation, StartsAlsoFromTheGroupThatFitsTheSceneBest) {
  const Eigen::Vector3f x(1, 0, 0), y(0, 1, 0), z(0, 0, 1);
  const TemplateBank bank = rotationBank({rot(3, z), rot(70, x), rot(-3, z), rot(0, y), rot(72, x)});
  const Camera camera;
  Hypothesis h = centredHypothesis(camera, 5, 90.f);
  const auto scored = [&](float largest_error, float other_error) {
    h.member_scores.assign(5, {});
    for (int i = 0; i < 5; ++i) {
      MemberScore& s = h.member_scores[static_cast<std::size_t>(i)];
      s.object_cells = 100, s.depth_pairs = 90, s.normal_pairs = 80;
      s.depth_error = i == 1 || i == 4 ? other_error : largest_error;
      s.angle_error = 0.1f;
    }
  };
  scored(0.02f, 0.001f);
  InitialRotation r = initialRotation(h, bank, camera);
  EXPECT_EQ(r.group_size, 3);
  EXPECT_LT(rotationDistance(r.R, Eigen::Matrix3f::Identity()) / kDeg, 0.5f);
  ASSERT_TRUE(r.by_fit.has_value());
  EXPECT_EQ(r.by_fit->votes, 2);
  EXPECT_LT(rotationDistance(r.by_fit->R, rot(71, x)) / kDeg, 0.5f);
  // Off: one start.
  InitialPoseParams one;
  one.second_start_by_fit = false;
  EXPECT_FALSE(initialRotation(h, bank, camera, one).by_fit.has_value());
  // The largest group fits best too: one start.
  scored(0.001f, 0.02f);
  EXPECT_FALSE(initialRotation(h, bank, camera).by_fit.has_value());
  // Without stage 4's scores (estimate_poses off, or scored elsewhere): one start.
  h.member_scores.clear();
  EXPECT_FALSE(initialRotation(h, bank, camera).by_fit.has_value());
  // A small part's starts (small_part_starts): the next largest groups as well, by_fit left
  // out where it is one of them.
  EXPECT_TRUE(initialRotation(h, bank, camera, {}, {}, 1).more.empty());
  scored(0.02f, 0.001f);
  r = initialRotation(h, bank, camera, {}, {}, 4);
  ASSERT_EQ(r.more.size(), 1u);  // two groups: about the identity (three) and 70-72 deg about x
  EXPECT_EQ(r.more[0].votes, 2);
  EXPECT_LT(rotationDistance(r.more[0].R, rot(71, x)) / kDeg, 0.5f);
  EXPECT_FALSE(r.by_fit.has_value());  // the best fit is that group: no third start
}

// Without depth no member has a fit to choose a second start by; a cluster of look-alike views
// (a jug lying on either side) can hold more templates of the wrong side than of the right
// one, whose template matched best. That group is a start too where it is none of the others.
TEST(InitialRotation, StartsAlsoFromTheBestMatchsGroupWhereTheLargestLeaveItOut) {
  const Eigen::Vector3f x(1, 0, 0), y(0, 1, 0), z(0, 0, 1);
  // Template 0, the best match, alone at 60 degrees about y; three about the identity, two at
  // 70-72 degrees about x.
  const TemplateBank bank = rotationBank({rot(60, y), rot(3, z), rot(70, x), rot(-3, z), rot(0, y), rot(72, x)});
  const Camera camera;
  Hypothesis h = centredHypothesis(camera, 6, 95.f);
  InitialRotation r = initialRotation(h, bank, camera, {}, {}, 2);
  EXPECT_EQ(r.group_size, 3);
  ASSERT_EQ(r.more.size(), 1u);
  EXPECT_EQ(r.more[0].votes, 2);
  ASSERT_TRUE(r.by_best_match.has_value());
  EXPECT_EQ(r.by_best_match->votes, 1);
  EXPECT_LT(rotationDistance(r.by_best_match->R, rot(60, y)) / kDeg, 0.5f);
  // Only frames without depth start from it.
  EXPECT_EQ(hypothesisStarts(h, {bank}, camera, {}, 2).size(), 2u);
  const std::vector<PoseCandidate> starts = hypothesisStarts(h, {bank}, camera, {}, 2, true);
  ASSERT_EQ(starts.size(), 3u);
  EXPECT_LT(rotationDistance(starts[2].start.R, rot(60, y)) / kDeg, 0.5f);
  // Three starts reach its group: none more.
  r = initialRotation(h, bank, camera, {}, {}, 3);
  EXPECT_EQ(r.more.size(), 2u);
  EXPECT_FALSE(r.by_best_match.has_value());
  // The best match in the largest group: none more.
  h.members[0].similarity = 80.f;
  std::stable_sort(h.members.begin(), h.members.end(),
                   [](const ClusterMember& a, const ClusterMember& b) { return a.similarity > b.similarity; });
  EXPECT_FALSE(initialRotation(h, bank, camera, {}, {}, 2).by_best_match.has_value());
}

/// The scene: a box on a wall at 0.8 m; the hypothesis: the same box rendered `offset` away.
struct TranslationCase {
  Camera camera;
  Mesh box;
  Pose truth, rendered;
  cv::Mat scene_depth;
  Rendering rendering;
};

TranslationCase translationCase(const Eigen::Vector3f& offset) {
  TranslationCase c;
  c.box.name = "box";
  // A 6 x 6 x 4 cm box, 1 cm-tessellated enough for the reference renderer.
  const float hx = 0.03f, hy = 0.03f, hz = 0.02f;
  c.box.vertices = {{-hx, -hy, -hz}, {hx, -hy, -hz}, {hx, hy, -hz}, {-hx, hy, -hz},
                    {-hx, -hy, hz},  {hx, -hy, hz},  {hx, hy, hz},  {-hx, hy, hz}};
  c.box.faces = {{0, 2, 1}, {0, 3, 2}, {4, 5, 6}, {4, 6, 7}, {0, 1, 5}, {0, 5, 4},
                 {2, 3, 7}, {2, 7, 6}, {1, 2, 6}, {1, 6, 5}, {0, 4, 7}, {0, 7, 3}};
  finishMesh(c.box);
  c.truth.R = rot(25.f, {1, 1, 0});
  c.truth.t = {0.02f, -0.01f, 0.75f};
  c.rendered = c.truth;
  c.rendered.t += offset;
  const Rendering scene = renderReference(c.box, c.camera, c.truth);
  c.scene_depth = scene.depth.clone();
  c.scene_depth.setTo(0.9f, scene.depth == 0.f);  // a wall behind
  c.rendering = renderReference(c.box, c.camera, c.rendered);
  return c;
}

TEST(InitialTranslation, MovesTheRenderedModelOntoTheScenePoints) {
  const Eigen::Vector3f offset(0.008f, -0.006f, 0.02f);
  const TranslationCase c = translationCase(offset);
  const InitialPose p = initialTranslation(c.rendering, c.rendered, c.scene_depth, c.camera, c.box.diameter);
  ASSERT_TRUE(p.ok) << p.why;
  const float before = offset.norm(), after = (p.pose.t - c.truth.t).norm();
  // Depth is corrected almost fully; the lateral part by the overlap's share.
  EXPECT_LT(std::abs(p.pose.t.z() - c.truth.t.z()), 0.004f);
  EXPECT_LT(after, 0.5f * before);
  EXPECT_TRUE(p.pose.R.isApprox(c.rendered.R));
  // The model points are the visible surface in the object frame: on the box.
  ASSERT_GT(p.model_points.size(), 500u);
  for (const auto& q : p.model_points) EXPECT_LE(q.cwiseAbs().maxCoeff(), 0.0301f);
  // The crop holds the box (and some wall within the depth band), not the whole frame.
  EXPECT_GT(p.scene_points.size(), p.object_pixels / 2);
  EXPECT_LT(p.scene_points.size(), std::size_t(c.camera.width * c.camera.height / 10));
}

// Stage 6 renders each candidate in its window only: the window holds every rendered pixel,
// and the windowed rendering gives the full frame's initial pose, model points and crop.
TEST(InitialTranslation, TheProjectedWindowGivesTheFullFramesResult) {
  const TranslationCase c = translationCase({0.008f, -0.006f, 0.02f});
  float radius = 0.f;
  for (const auto& v : c.box.vertices) radius = std::max(radius, (v - c.box.bboxCentre()).norm());
  const cv::Rect window = projectedWindow(c.rendered, c.box.bboxCentre(), radius, c.camera);
  const cv::Rect drawn = cv::boundingRect(c.rendering.depth > 0.f);
  EXPECT_EQ(window & drawn, drawn);
  EXPECT_LT(window.area(), c.camera.width * c.camera.height / 10);
  const Rendering in_window = renderReference(c.box, windowCamera(c.camera, window), c.rendered);
  ASSERT_EQ(in_window.depth.size(), window.size());
  const InitialPose whole = initialTranslation(c.rendering, c.rendered, c.scene_depth, c.camera, c.box.diameter);
  const InitialPose part =
      initialTranslation(in_window, c.rendered, c.scene_depth, c.camera, c.box.diameter, {}, window);
  ASSERT_TRUE(whole.ok && part.ok);
  // The window's principal point differs by whole pixels: the same coverage, depths to rounding.
  EXPECT_EQ(part.mask_pixels, whole.mask_pixels);
  EXPECT_EQ(part.object_pixels, whole.object_pixels);
  EXPECT_EQ(part.scene_points.size(), whole.scene_points.size());
  EXPECT_LT((part.pose.t - whole.pose.t).norm(), 1e-5f);
  // Off the image, or behind the camera: no window.
  Pose away = c.rendered;
  away.t.x() += 5.f;
  EXPECT_TRUE(projectedWindow(away, c.box.bboxCentre(), radius, c.camera).empty());
  away = c.rendered;
  away.t.z() = -0.5f;
  EXPECT_TRUE(projectedWindow(away, c.box.bboxCentre(), radius, c.camera).empty());
  // A window that is not the rendering's size is a caller's mistake.
  EXPECT_THROW(initialTranslation(c.rendering, c.rendered, c.scene_depth, c.camera, 0.1f, {}, window), InputError);
}

// The cluster score's depth offset compares z, and off the optical axis the scene's z of an
// object is its range times cos(theta): the template's range plus the offset is the z-range,
// which rangeOnRay turns into the range along the ray. Unconverted, a box 0.8 m away at 30
// degrees off the axis is placed about 10 cm short.
TEST(InitialTranslation, TheDepthOffsetIsInZAndTheRangeIsAlongTheRay) {
  const TranslationCase c = translationCase({0.f, 0.f, 0.f});
  const float range = 0.8f;
  // The template: the box on the optical axis at `range`, as training renders it.
  Pose on_axis;
  on_axis.R = rot(25.f, {1, 1, 0});
  on_axis.t = Eigen::Vector3f(0.f, 0.f, range);
  // The scene: the same view of it on the ray through a pixel near the top-left corner.
  const float px = 60.f, py = 50.f;
  Pose off_axis;
  off_axis.R = viewingRayRotation(px, py, c.camera) * on_axis.R;
  off_axis.t = poseAtRange(off_axis.R, px, py, range, Eigen::Vector3f::Zero(), c.camera).t;
  const Rendering tmpl = renderReference(c.box, c.camera, on_axis), scene = renderReference(c.box, c.camera, off_axis);
  const auto meanDepth = [](const Rendering& r) { return static_cast<float>(cv::mean(r.depth, r.depth > 0.f)[0]); };
  const float offset = meanDepth(scene) - meanDepth(tmpl);
  const float theta = std::acos(off_axis.t.normalized().z());
  ASSERT_GT(theta / kDeg, 28.f);
  EXPECT_GT(std::abs(range + offset - range), 0.05f);  // the plain sum: centimetres short
  EXPECT_NEAR(rangeOnRay(range, offset, px, py, c.camera), range, 0.006f);
  // On the axis the two agree.
  EXPECT_FLOAT_EQ(rangeOnRay(range, 0.01f, static_cast<float>(c.camera.cx), static_cast<float>(c.camera.cy), c.camera),
                  range + 0.01f);
}

TEST(InitialTranslation, AnOccluderDoesNotPullTheModelForward) {
  TranslationCase c = translationCase({0.f, 0.f, 0.015f});
  // Something 10 cm in front covers the left half of the box.
  const cv::Rect box = cv::boundingRect(c.rendering.depth > 0.f);
  c.scene_depth(cv::Rect(box.x, box.y, box.width / 2, box.height)).setTo(0.65f);
  const InitialPose p = initialTranslation(c.rendering, c.rendered, c.scene_depth, c.camera, c.box.diameter);
  ASSERT_TRUE(p.ok) << p.why;
  EXPECT_LT(std::abs(p.pose.t.z() - c.truth.t.z()), 0.004f);
}

// A start more than the depth band short (here 6 cm, the band 3 cm for this 9 cm box) pairs no
// scene pixel: everything under the mask looks like background. The second try moves it by
// the median depth difference under the mask, and the shift then lands on the box.
TEST(InitialTranslation, AStartCentimetresShortGetsASecondTry) {
  const TranslationCase c = translationCase({0.f, 0.f, -0.06f});
  ASSERT_LT(InitialPoseParams{}.depth_band_fraction * c.box.diameter, 0.04f);
  const InitialPose p = initialTranslation(c.rendering, c.rendered, c.scene_depth, c.camera, c.box.diameter);
  ASSERT_TRUE(p.ok) << p.why;
  EXPECT_LT(std::abs(p.pose.t.z() - c.truth.t.z()), 0.006f);
  EXPECT_GT(p.object_pixels, p.mask_pixels / 2);
}

TEST(InitialTranslation, ABlackHoleIsRejectedWithAReason) {
  TranslationCase c = translationCase({0.f, 0.f, 0.f});
  c.scene_depth.setTo(0.f);
  const InitialPose p = initialTranslation(c.rendering, c.rendered, c.scene_depth, c.camera, c.box.diameter);
  EXPECT_FALSE(p.ok);
  EXPECT_NE(p.why.find("have scene depth near it"), std::string::npos) << p.why;
  EXPECT_TRUE(p.scene_points.empty());
  // A rendering of another size is a caller's mistake, reported as such.
  const cv::Mat small(10, 10, CV_32FC1, cv::Scalar(0.5f));
  EXPECT_NE(test::inputErrorOf([&] { initialTranslation(c.rendering, c.rendered, small, c.camera, 0.1f); }).find("10x10"),
            std::string::npos);
  InitialPoseParams bad;
  bad.rotation_cluster_deg = 0.f;
  EXPECT_THROW(validateInitialPoseParams(bad), InputError);
  bad = {};
  bad.resting_poses_starts = 0;
  EXPECT_THROW(validateInitialPoseParams(bad), InputError);
}

/// A start whose first fit put the object's centre at `t` with these measurements.
PoseCandidate firstFitStart(int bank, const Eigen::Vector3f& t, float collision, float see_through, float silhouette,
                            float contour = 1.f) {
  PoseCandidate c;
  c.detection.bank = bank;
  c.initial.ok = true;
  c.first_fit.pose.t = t;
  c.first_evidence.collision.collision_rate = collision;
  c.first_evidence.depth.seen_through = see_through;
  c.first_evidence.silhouette_support = silhouette;
  c.first_evidence.contour_edges = contour;
  // RefineParams and VerifyParams at their defaults: share 0.75 (contour 0.6), two a place.
  c.first_fit_min_collision = c.refine.first_fit_share * c.verify.threshold;
  return c;
}

/// Stage 8's measurements, passing every test or failing the collision test.
void measure(PoseCandidate& c, bool passes) {
  c.measured = true;
  c.evidence.collision.model_points = 1000;
  c.evidence.collision.collision_rate = passes ? 0.8f : 0.2f;
  c.evidence.silhouette_support = 1.f;
  c.evidence.contour_edges = 1.f;
}

std::vector<TemplateBank> twoTenCentimetreObjects() {
  std::vector<TemplateBank> banks(2);
  banks[0].object = "cup";
  banks[1].object = "carton";
  for (auto& b : banks) b.diameter = 0.1f;  // centre at the origin
  return banks;
}

TEST(StageEight, PointsTheSceneHidesDoNotCountAgainstTheCollisionRate) {
  PoseCandidate c;
  measure(c, true);
  c.evidence.collision.collision_rate = 0.3f;  // under the threshold of 0.4 counted over every point
  EXPECT_NE(stageEightShortfall(c).find("collision rate 0.30"), std::string::npos) << "nothing hidden";
  c.evidence.depth.occluded = 0.3f;  // 0.3 of 0.7 in sight: 0.43
  EXPECT_EQ(stageEightShortfall(c), "") << "a part 70 % in sight collides with at most 70 % of its points";
  EXPECT_TRUE(collides(c));
  c.verify.occlusion_credit = 0.f;
  EXPECT_NE(stageEightShortfall(c).find("is not above 0.40"), std::string::npos) << "the paper's rate";
  c.verify.occlusion_credit = 0.5f;
  c.evidence.collision.collision_rate = 0.15f;
  c.evidence.depth.occluded = 0.8f;  // 0.15 of 0.2 in sight, but at most half counts as hidden: 0.30
  EXPECT_NE(stageEightShortfall(c).find("(0.30 of the points the scene does not hide)"), std::string::npos)
      << stageEightShortfall(c);
  EXPECT_FALSE(collides(c));
}

TEST(StageEight, TheOutlineOnEdgesTestIsOffUntilAsked) {
  PoseCandidate c;
  measure(c, true);
  c.evidence.outline_on_edges = 0.4f;
  EXPECT_EQ(stageEightShortfall(c), "") << "off by default";
  c.verify.min_outline_on_edges = 0.7f;  // a pile of small turned parts
  EXPECT_NE(stageEightShortfall(c).find("only 40% of its visible outline lies on an image edge"), std::string::npos)
      << stageEightShortfall(c);
  c.evidence.outline_on_edges = 0.8f;
  EXPECT_EQ(stageEightShortfall(c), "");
}

// The size test (silhouette_scale) is for parts of 10 cm or more trained nearer than 0.5 m (a
// spark-plug key in a pile): not for a part under 10 cm (its holed depth moves the estimate),
// nor for one trained farther; a scale not measured (NaN) passes.
TEST(StageEight, TheSizeTestIsForLargePartsTrainedAtCloseRange) {
  PoseCandidate c;
  measure(c, true);
  c.evidence.silhouette_scale = 1.13f;
  TemplateBank key;  // 17 cm, trained at 0.3-0.5 m
  key.diameter = 0.17f;
  key.params.views.radii = {0.3f, 0.5f, 0.05f};
  const VerifyParams defaults;
  EXPECT_FLOAT_EQ(defaults.max_silhouette_scale, 1.05f);
  c.verify = partVerifyParams(defaults, key);
  EXPECT_NE(stageEightShortfall(c).find("silhouette around it is 13% larger than the model"), std::string::npos)
      << stageEightShortfall(c);
  c.evidence.silhouette_scale = 1.04f;
  EXPECT_EQ(stageEightShortfall(c), "");
  c.evidence.silhouette_scale = std::numeric_limits<float>::quiet_NaN();
  EXPECT_EQ(stageEightShortfall(c), "");
  key.params.views.radii = {0.6f, 1.2f, 0.1f};  // seen from farther: its outline spans too few pixels
  EXPECT_EQ(partVerifyParams(defaults, key).max_silhouette_scale, 0.f);
  TemplateBank nozzle = key;  // 58 mm, trained at 0.3-0.5 m
  nozzle.diameter = 0.058f;
  nozzle.params.views.radii = {0.3f, 0.5f, 0.05f};
  EXPECT_EQ(partVerifyParams(defaults, nozzle).max_silhouette_scale, 0.f);
}

// A part under 10 cm asks more of its colour; one that is a body of revolution (a nozzle, a
// pin) also asks 0.7 of its outline on the image's edges. A flat part of that size keeps the
// outline test off (a bracket's right poses measure from 0.48), and so does a larger object.
TEST(StageEight, ASmallTurnedPartsOutlineMustLieOnItsEdges) {
  Mesh nozzle = procedural::lathe({{0.f, 0.f}, {0.01f, 0.f}, {0.01f, 0.058f}, {0.f, 0.058f}}, 48, {0.6f, 0.6f, 0.6f});
  finishMesh(nozzle);
  const auto bankOf = [](const Mesh& mesh) {
    TemplateBank bank;
    bank.mesh = mesh;
    bank.diameter = mesh.diameter;
    bank.near_symmetries = findNearSymmetries(mesh, 0.03f * mesh.diameter);
    return bank;
  };
  const TemplateBank turned = bankOf(nozzle);
  ASSERT_TRUE(revolutionAxis(turned.near_symmetries).has_value());
  const VerifyParams defaults;
  EXPECT_EQ(defaults.min_outline_on_edges, 0.f);
  const VerifyParams small_turned = partVerifyParams(defaults, turned);
  EXPECT_FLOAT_EQ(small_turned.min_outline_on_edges, 0.7f);
  EXPECT_FLOAT_EQ(small_turned.min_colour_agreement, 0.45f);

  TemplateBank flat = bankOf(test::boxMesh({0.04f, 0.02f, 0.012f}));
  ASSERT_FALSE(revolutionAxis(flat.near_symmetries).has_value());
  EXPECT_FLOAT_EQ(partVerifyParams(defaults, flat).min_outline_on_edges, 0.f);
  EXPECT_FLOAT_EQ(partVerifyParams(defaults, flat).min_colour_agreement, 0.45f);
  flat.symmetric = true;  // trained --symmetric: the user says it is a body of revolution
  EXPECT_FLOAT_EQ(partVerifyParams(defaults, flat).min_outline_on_edges, 0.7f);

  TemplateBank large = turned;  // the same shape 14 cm across (a cup): the defaults stand
  large.diameter = 0.14f;
  EXPECT_FLOAT_EQ(partVerifyParams(defaults, large).min_outline_on_edges, 0.f);
  EXPECT_FLOAT_EQ(partVerifyParams(defaults, large).min_colour_agreement, 0.2f);

  VerifyParams stricter;  // a user's higher setting for every object stays
  stricter.min_outline_on_edges = 0.8f;
  EXPECT_FLOAT_EQ(partVerifyParams(stricter, turned).min_outline_on_edges, 0.8f);
}

TEST(FirstFit, StopsStartsShortOfStageEightsLimitsAndSaysWhy) {
  std::vector<PoseCandidate> c;
  c.push_back(firstFitStart(0, {0.0f, 0, 0.7f}, 0.28f, 0.0f, 1.0f));   // collision under 0.75 x 0.4
  c.push_back(firstFitStart(0, {0.2f, 0, 0.7f}, 0.35f, 0.0f, 0.40f));  // silhouette under 0.75 x 0.55
  c.push_back(firstFitStart(0, {0.4f, 0, 0.7f}, 0.35f, 0.25f, 0.9f));  // sees through more than 0.15 / 0.75
  c.push_back(firstFitStart(0, {0.6f, 0, 0.7f}, 0.35f, 0.1f, 0.5f));   // near enough on every test
  // Above the limit's collision rate and seeing through itself: pulled aside by a table in
  // the first fit, its outline tests wait for MLS and ICP.
  c.push_back(firstFitStart(0, {0.8f, 0, 0.7f}, 0.45f, 0.25f, 0.2f));
  // Above the limit but lying on the scene's surfaces without a depth step at its outline.
  c.push_back(firstFitStart(0, {1.0f, 0, 0.7f}, 0.55f, 0.01f, 0.2f));
  c.push_back(firstFitStart(0, {1.2f, 0, 0.7f}, 0.55f, 0.0f, 0.9f, 0.2f));  // image edges under 0.6 x 0.45
  PoseCandidate second_try = firstFitStart(0, {1.4f, 0, 0.7f}, 0.45f, 0.0f, 0.9f);
  second_try.verify.threshold = 0.6f;
  second_try.first_fit_min_collision = 0.5f;  // 0.6 less the plain limit's margin, 0.25 x 0.4
  c.push_back(second_try);
  PoseCandidate unplaced = firstFitStart(0, {1.6f, 0, 0.7f}, 0.f, 1.f, 0.f);
  unplaced.initial.ok = false;
  c.push_back(unplaced);
  screenStarts(c);
  EXPECT_NE(c[0].screened.find("collision rate 0.28 of the points the scene does not hide after the first fit"),
            std::string::npos)
      << c[0].screened;
  EXPECT_NE(c[1].screened.find("40% of the outline"), std::string::npos) << c[1].screened;
  EXPECT_NE(c[2].screened.find("sees through 25%"), std::string::npos) << c[2].screened;
  EXPECT_TRUE(c[3].refinable()) << c[3].screened;
  EXPECT_TRUE(c[4].refinable()) << c[4].screened;
  EXPECT_NE(c[5].screened.find("20% of the outline"), std::string::npos) << c[5].screened;
  EXPECT_NE(c[6].screened.find("20% of its visible outline meets an edge"), std::string::npos) << c[6].screened;
  EXPECT_NE(c[7].screened.find("at least 0.50 to go on"), std::string::npos) << c[7].screened;
  EXPECT_TRUE(c[8].screened.empty());  // stage 6 said why already
  EXPECT_FALSE(c[8].refinable());
}

TEST(FirstFit, KeepsTheBestTwoOfAnObjectInAPlaceAndLetsAnotherObjectWaitForThem) {
  const auto banks = twoTenCentimetreObjects();
  std::vector<PoseCandidate> c;
  c.push_back(firstFitStart(0, {0.000f, 0, 0.7f}, 0.5f, 0.f, 0.6f));
  c.push_back(firstFitStart(0, {0.010f, 0, 0.7f}, 0.7f, 0.f, 0.9f));  // best
  c.push_back(firstFitStart(0, {0.020f, 0, 0.7f}, 0.6f, 0.f, 0.9f));  // second
  c.push_back(firstFitStart(1, {0.005f, 0, 0.7f}, 0.4f, 0.f, 0.6f));  // another object in that place
  c.push_back(firstFitStart(0, {0.100f, 0, 0.7f}, 0.4f, 0.f, 0.6f));  // 1 diameter away
  EXPECT_EQ(nextRound(c, banks, 0.3f), (std::vector<std::size_t>{1, 2, 4}));
  EXPECT_NE(c[0].screened.find("2 better starts of cup in the same place"), std::string::npos) << c[0].screened;
  EXPECT_TRUE(c[3].screened.empty()) << c[3].screened;  // waits for the cups
  measure(c[1], false);
  measure(c[2], true);
  measure(c[4], true);
  EXPECT_TRUE(nextRound(c, banks, 0.3f).empty());  // a cup passed: the carton would lose the place
  EXPECT_NE(c[3].screened.find("a better start of cup in the same place passed stage 8"), std::string::npos)
      << c[3].screened;
  // Had both cups failed, the carton would have gone next.
  for (auto& x : c) x.screened.clear(), x.measured = false;
  EXPECT_EQ(nextRound(c, banks, 0.3f), (std::vector<std::size_t>{1, 2, 4}));
  measure(c[1], false);
  measure(c[2], false);
  measure(c[4], true);
  EXPECT_EQ(nextRound(c, banks, 0.3f), (std::vector<std::size_t>{3}));
  // 0: every start of an object goes.
  for (auto& x : c) x.screened.clear(), x.measured = false, x.refine.first_fit_per_place = 0;
  EXPECT_EQ(nextRound(c, banks, 0.3f), (std::vector<std::size_t>{0, 1, 2, 4}));
  // With the first fit off, every placed start goes in one round.
  for (auto& x : c) x.screened.clear(), x.measured = false, x.refine.first_fit = false;
  EXPECT_EQ(nextRound(c, banks, 0.3f), (std::vector<std::size_t>{0, 1, 2, 3, 4}));
  for (auto& x : c) measure(x, false);
  EXPECT_TRUE(nextRound(c, banks, 0.3f).empty());
}

TEST(FirstFit, StopsAStartAtTheSamePoseAsABetterOneOfItsObject) {
  const auto banks = twoTenCentimetreObjects();
  std::vector<PoseCandidate> c;
  c.push_back(firstFitStart(0, {0.000f, 0, 0.7f}, 0.7f, 0.f, 0.9f));  // best
  c.push_back(firstFitStart(0, {0.003f, 0, 0.7f}, 0.6f, 0.f, 0.9f));  // 3 mm, 6 degrees away: one pose
  c[1].first_fit.pose.R = rot(6.f, {0, 0, 1});
  c.push_back(firstFitStart(0, {0.003f, 0, 0.7f}, 0.5f, 0.f, 0.9f));  // 3 mm, 20 degrees: another pose
  c[2].first_fit.pose.R = rot(20.f, {0, 0, 1});
  c.push_back(firstFitStart(1, {0.001f, 0, 0.7f}, 0.5f, 0.f, 0.9f));  // another object: waits
  EXPECT_EQ(nextRound(c, banks, 0.3f), (std::vector<std::size_t>{0, 2}));
  EXPECT_NE(c[1].screened.find("the same pose after the first fit as a better start of cup"), std::string::npos)
      << c[1].screened;
  EXPECT_TRUE(c[3].screened.empty()) << c[3].screened;
  // 0 degrees: only one pose exactly is the same.
  for (auto& x : c) x.screened.clear(), x.refine.first_fit_twin_angle_deg = 0.f;
  EXPECT_EQ(nextRound(c, banks, 0.3f), (std::vector<std::size_t>{0, 1}));
}

TEST(FirstFit, StopsAStartWhoseColoursDisagreeWithTheFrame) {
  TranslationCase scene = translationCase({0.f, 0.f, 0.f});
  Mesh box = scene.box;
  box.colours.assign(box.vertices.size(), Eigen::Vector3f(0.8f, 0.2f, 0.1f));  // orange-red
  TemplateBank bank;
  bank.object = "box";
  bank.mesh = box;
  bank.diameter = box.diameter;
  MeshRenderer renderer(test::context(), box);
  PoseObject object;
  object.bank = &bank;
  object.renderer = &renderer;
  object.bounding_radius = 0.5f * box.diameter;
  const Rendering seen = renderer.render(scene.camera, {scene.truth}).front();
  cv::Mat red = seen.bgr.clone();
  red.setTo(cv::Scalar(128, 128, 128), seen.depth == 0.f);  // a grey wall behind
  std::vector<cv::Mat> channels;
  cv::split(red, channels);
  std::swap(channels[1], channels[2]);
  cv::Mat green;
  cv::merge(channels, green);
  const auto start = [&] {
    PoseCandidate c = firstFitStart(0, scene.truth.t, 0.8f, 0.f, 0.9f);
    c.first_fit.pose = scene.truth;
    return std::vector<PoseCandidate>{c};
  };
  std::vector<PoseCandidate> same = start(), other = start();
  firstFitColours(same, {object}, poseFrame(scene.camera, scene.scene_depth, red), 2);
  EXPECT_TRUE(same[0].refinable()) << same[0].screened;
  EXPECT_GT(same[0].first_colour, 0.8f);
  firstFitColours(other, {object}, poseFrame(scene.camera, scene.scene_depth, green), 2);
  EXPECT_LT(other[0].first_colour, 0.1f);
  EXPECT_NE(other[0].screened.find("its colours do not match the scene's after the first fit"), std::string::npos)
      << other[0].screened;
  // A mesh without colours is not rendered, and goes on.
  bank.mesh.colours.clear();
  std::vector<PoseCandidate> grey = start();
  firstFitColours(grey, {object}, poseFrame(scene.camera, scene.scene_depth, green), 2);
  EXPECT_TRUE(grey[0].refinable());
  EXPECT_TRUE(std::isnan(grey[0].first_colour));
}

}  // namespace
}  // namespace vkpose
