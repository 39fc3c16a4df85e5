// Pose errors, matching and scores: ground truth scored against itself is perfect, each kind
// of mistake costs exactly what the protocol says, and the BOP CSV reads back what was written.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <numbers>
#include <random>
#include <sstream>

#include <Eigen/Geometry>
#include <nlohmann/json.hpp>
#include <unistd.h>

#include "test_support.hpp"
#include "vkpose/error.hpp"
#include "vkpose/evaluation.hpp"

namespace vkpose {
namespace {

namespace fs = std::filesystem;

PoseEstimate asEstimate(const GroundTruthPose& g, float score) { return {g.obj_id, score, g.R, g.t}; }

ModelInfo modelInfo(int obj_id, float diameter) {
  ModelInfo m;
  m.obj_id = obj_id;
  m.diameter = diameter;
  return m;
}

Eigen::Matrix3f rotation(float degrees, const Eigen::Vector3f& axis) {
  return Eigen::AngleAxisf(degrees * std::numbers::pi_v<float> / 180.f, axis.normalized()).toRotationMatrix();
}

// ---------------------------------------------------------------------------------------
// Pose errors on synthetic point sets

TEST(Metrics, PointIndexFindsTheExactNearestPoint) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(-0.1f, 0.1f);
  std::vector<Eigen::Vector3f> points;
  for (int i = 0; i < 3000; ++i) points.emplace_back(u(rng), u(rng), 0.3f * u(rng));
  for (int i = 0; i < 50; ++i) points.push_back(points[static_cast<std::size_t>(i)]);  // duplicates
  for (int i = 0; i < 200; ++i)
    points.emplace_back(0.05f, 0.05f, 0.001f * static_cast<float>(i % 3));  // a tight cluster
  const PointIndex index(points);
  ASSERT_EQ(index.points().size(), points.size());
  for (int q = 0; q < 2000; ++q) {
    const Eigen::Vector3f p(2 * u(rng), 2 * u(rng), 2 * u(rng));
    float best = std::numeric_limits<float>::infinity();
    for (const auto& x : points) best = std::min(best, (x - p).squaredNorm());
    ASSERT_EQ(index.nearestDistance(p), std::sqrt(best)) << q;
  }
  EXPECT_EQ(index.nearestDistance(points[5]), 0.f);
  EXPECT_TRUE(std::isinf(PointIndex().nearestDistance(Eigen::Vector3f::Zero())));
  EXPECT_FLOAT_EQ(PointIndex({Eigen::Vector3f(1, 2, 3)}).nearestDistance(Eigen::Vector3f(1, 2, 5)), 2.f);
}

/// A cylinder of radius r about z: 360 points on each of 5 circles.
std::vector<Eigen::Vector3f> cylinder(float r) {
  std::vector<Eigen::Vector3f> points;
  for (int h = 0; h < 5; ++h)
    for (int a = 0; a < 360; ++a) {
      const float rad = static_cast<float>(a) * std::numbers::pi_v<float> / 180.f;
      points.emplace_back(r * std::cos(rad), r * std::sin(rad), 0.02f * static_cast<float>(h));
    }
  return points;
}

TEST(Metrics, AddAndAdiOfKnownMotions) {
  const auto points = cylinder(0.05f);
  const PointIndex index(points);
  const Eigen::Matrix3f R_gt = rotation(30, {1, 2, 3});
  const Eigen::Vector3f t_gt(0.1f, -0.05f, 0.9f);
  EXPECT_FLOAT_EQ(addError(points, R_gt, t_gt, R_gt, t_gt), 0.f);
  EXPECT_NEAR(adiError(index, R_gt, t_gt, R_gt, t_gt), 0.f, 1e-7f);  // R^T R is I to float precision
  // A pure translation moves every point by the same distance.
  const Eigen::Vector3f shift(0.003f, -0.004f, 0.012f);
  EXPECT_NEAR(addError(points, R_gt, t_gt + shift, R_gt, t_gt), 0.013f, 1e-6f);
  EXPECT_LE(adiError(index, R_gt, t_gt + shift, R_gt, t_gt), 0.013f + 1e-6f);
  // A turn about the cylinder's own axis: ADI sees the same surface, ADD the moved points.
  // Turning by 90 degrees maps every point of a circle onto a point of it; ADD is the chord.
  const Eigen::Matrix3f R_est = R_gt * rotation(90, {0, 0, 1});
  EXPECT_NEAR(adiError(index, R_est, t_gt, R_gt, t_gt), 0.f, 1e-6f);
  EXPECT_NEAR(addError(points, R_est, t_gt, R_gt, t_gt), 0.05f * std::sqrt(2.f), 1e-6f);
  // Half a degree: the closest point is at most half a one-degree chord away.
  const Eigen::Matrix3f R_half = R_gt * rotation(0.5f, {0, 0, 1});
  EXPECT_LT(adiError(index, R_half, t_gt, R_gt, t_gt), 0.05f * 0.0088f);
  // A turn about another axis is an error for both.
  const Eigen::Matrix3f R_tilt = R_gt * rotation(90, {1, 0, 0});
  EXPECT_GT(adiError(index, R_tilt, t_gt, R_gt, t_gt), 0.01f);
}

// ---------------------------------------------------------------------------------------
// Matching on a synthetic object: the protocol's rules one at a time

class MetricsMatching : public ::testing::Test {
 protected:
  static constexpr float kDiameter = 0.1f;  // metres: correct below 0.015
  std::map<int, EvalModel> models;
  void SetUp() override {
    std::vector<Eigen::Vector3f> points;  // an asymmetric box: 0.08 x 0.05 x 0.03 m, 6x6x6 grid
    for (int i = 0; i < 6; ++i)
      for (int j = 0; j < 6; ++j)
        for (int k = 0; k < 6; ++k) points.emplace_back(0.016f * i - 0.04f, 0.01f * j - 0.025f, 0.006f * k - 0.015f);
    models.emplace(1, makeEvalModel(modelInfo(1, kDiameter), points));
    models.emplace(2, makeEvalModel(modelInfo(2, kDiameter), points));
  }
  static GroundTruthPose gt(int obj_id, float x, float visib = 1.f) {
    return {obj_id, Eigen::Matrix3f::Identity(), Eigen::Vector3f(x, 0.f, 1.f), visib};
  }
  static PoseEstimate est(int obj_id, float x, float score) {
    return {obj_id, score, Eigen::Matrix3f::Identity(), Eigen::Vector3f(x, 0.f, 1.f)};
  }
};

TEST_F(MetricsMatching, EachEstimateTakesTheClosestCorrectFreeInstanceBestScoreFirst) {
  // Instances at x = 0 and x = 0.01 (both within 0.015 of an estimate at 0.006).
  const std::vector<GroundTruthPose> gts = {gt(1, 0.f), gt(1, 0.01f)};
  // The best estimate is closer to the second instance and takes it; the next takes the other.
  const auto r = evaluateImage({est(1, 0.004f, 0.5f), est(1, 0.006f, 0.9f)}, gts, models);
  EXPECT_EQ(r.matches[1].gt, 1);
  EXPECT_NEAR(r.matches[1].error, 0.004f, 1e-6f);
  EXPECT_EQ(r.matches[0].gt, 0);
  EXPECT_NEAR(r.matches[0].error, 0.004f, 1e-6f);
  EXPECT_EQ(r.counts.at(1).tp, 2);
  EXPECT_EQ(r.counts.at(1).fp, 0);
  EXPECT_EQ(r.counts.at(1).fn, 0);

  // Greedy by score: the best estimate takes its closest correct instance first, the next one
  // what is left; an estimate whose only correct instance is taken is a false positive.
  const auto g = evaluateImage({est(1, 0.011f, 0.2f), est(1, 0.006f, 0.9f)}, {gt(1, 0.f), gt(1, 0.02f)}, models);
  EXPECT_EQ(g.matches[1].gt, 0);  // 0.006 from x = 0, 0.014 from x = 0.02
  EXPECT_EQ(g.matches[0].gt, 1);  // 0.009 from x = 0.02
  const auto taken = evaluateImage({est(1, 0.004f, 0.2f), est(1, 0.006f, 0.9f)}, {gt(1, 0.f), gt(1, 0.03f)}, models);
  EXPECT_EQ(taken.matches[1].gt, 0);
  EXPECT_EQ(taken.matches[0].gt, -1);
  EXPECT_EQ(taken.counts.at(1).tp, 1);
  EXPECT_EQ(taken.counts.at(1).fp, 1);
  EXPECT_EQ(taken.counts.at(1).fn, 1);
}

TEST_F(MetricsMatching, ObjectsAreMatchedSeparatelyAndEqualScoresKeepTheirOrder) {
  // An estimate of object 2 on an instance of object 1 is a false positive, not a match.
  const auto r = evaluateImage({est(2, 0.f, 1.f), est(1, 0.f, 1.f), est(1, 0.f, 1.f)}, {gt(1, 0.f)}, models);
  EXPECT_EQ(r.matches[0].gt, -1);
  EXPECT_EQ(r.matches[1].gt, 0);
  EXPECT_EQ(r.matches[2].gt, -1);  // the duplicate, later in order
  EXPECT_EQ(r.counts.at(1).tp, 1);
  EXPECT_EQ(r.counts.at(1).fp, 1);
  EXPECT_EQ(r.counts.at(2).fp, 1);
  EXPECT_EQ(r.counts.at(2).fn, 0);
}

TEST_F(MetricsMatching, ThresholdIsStrictlyBelowKmTimesDiameter) {
  EXPECT_EQ(evaluateImage({est(1, 0.0149f, 1.f)}, {gt(1, 0.f)}, models).counts.at(1).tp, 1);
  const auto miss = evaluateImage({est(1, 0.0151f, 1.f)}, {gt(1, 0.f)}, models).counts.at(1);
  EXPECT_EQ(miss.tp, 0);
  EXPECT_EQ(miss.fp, 1);
  EXPECT_EQ(miss.fn, 1);
  EvalParams loose;
  loose.k_m = 0.2f;
  EXPECT_EQ(evaluateImage({est(1, 0.0151f, 1.f)}, {gt(1, 0.f)}, models, loose).counts.at(1).tp, 1);
}

TEST_F(MetricsMatching, BarelyVisibleInstancesCanBeLeftOut) {
  const std::vector<GroundTruthPose> gts = {gt(1, 0.f), gt(1, 0.1f, 0.05f)};
  // By default every instance counts: missing the hidden one is a false negative.
  EXPECT_EQ(evaluateImage({est(1, 0.f, 1.f)}, gts, models).counts.at(1).fn, 1);
  EvalParams params;
  params.min_visib_fract = 0.1f;
  const auto missed = evaluateImage({est(1, 0.f, 1.f)}, gts, models, params).counts.at(1);
  EXPECT_EQ(missed.tp, 1);
  EXPECT_EQ(missed.fn, 0);
  // Finding it is neither a true nor a false positive.
  const auto found = evaluateImage({est(1, 0.f, 1.f), est(1, 0.1f, 0.5f)}, gts, models, params);
  EXPECT_EQ(found.matches[1].gt, 1);
  EXPECT_TRUE(found.matches[1].ignored);
  EXPECT_EQ(found.counts.at(1).tp, 1);
  EXPECT_EQ(found.counts.at(1).fp, 0);
  EXPECT_EQ(found.counts.at(1).fn, 0);
}

TEST_F(MetricsMatching, InstancesAreCountedByHowVisibleTheyAre) {
  // Four instances 0.05 m apart (no estimate is correct for two of them), 5 %, 30 %, 60 % and
  // 100 % visible; the estimates find the 30 % and the 100 % one.
  const std::vector<GroundTruthPose> gts = {gt(1, 0.f, 0.05f), gt(1, 0.05f, 0.3f), gt(1, 0.1f, 0.6f),
                                            gt(1, 0.15f, 1.f)};
  const auto r = evaluateImage({est(1, 0.05f, 0.9f), est(1, 0.15f, 0.8f), est(1, 0.3f, 0.7f)}, gts, models);
  const VisibilityRecall& v = r.by_visibility.at(1);
  EXPECT_EQ(v.instances, (std::array<int, 5>{1, 1, 0, 1, 1}));
  EXPECT_EQ(v.found, (std::array<int, 5>{0, 1, 0, 0, 1}));
  // The bins are 0.2 wide, each from its lower edge; 1 and above go to the top one.
  EXPECT_EQ(VisibilityRecall::binOf(0.f), 0);
  EXPECT_EQ(VisibilityRecall::binOf(0.1999f), 0);
  EXPECT_EQ(VisibilityRecall::binOf(0.2f), 1);
  EXPECT_EQ(VisibilityRecall::binOf(0.6f), 3);
  EXPECT_EQ(VisibilityRecall::binOf(0.8f), 4);
  EXPECT_EQ(VisibilityRecall::binOf(1.f), 4);
  EXPECT_EQ(VisibilityRecall::binOf(1.5f), 4);
  EXPECT_EQ(VisibilityRecall::binOf(-1.f), 0);
  EXPECT_EQ(VisibilityRecall::binOf(std::nanf("")), 0);

  // Instances left out of the scores (below min_visib_fract) are left out here as well.
  EvalParams params;
  params.min_visib_fract = 0.1f;
  const auto left_out = evaluateImage({est(1, 0.f, 0.9f)}, gts, models, params);
  EXPECT_EQ(left_out.by_visibility.at(1).instances, (std::array<int, 5>{0, 1, 0, 1, 1}));
  EXPECT_EQ(left_out.by_visibility.at(1).found, (std::array<int, 5>{}));

  // Summing images adds bin by bin.
  VisibilityRecall sum = v;
  sum += left_out.by_visibility.at(1);
  EXPECT_EQ(sum.instances, (std::array<int, 5>{1, 2, 0, 2, 2}));
  EXPECT_EQ(sum.found, (std::array<int, 5>{0, 1, 0, 0, 1}));
}

TEST(Metrics, TheReportListsInstancesFoundByVisibility) {
  EvalReport report;
  report.objects = {1, 2};
  MethodEvaluation m;
  m.summary = summarize({{1, {2, 0, 1}}, {2, {1, 0, 0}}});
  m.by_visibility[1].instances = {0, 0, 1, 0, 2};
  m.by_visibility[1].found = {0, 0, 0, 0, 2};
  m.by_visibility[2].instances = {0, 0, 0, 0, 1};
  m.by_visibility[2].found = {0, 0, 0, 0, 1};
  report.methods.push_back(m);
  // All objects together, a bin each.
  EXPECT_NE(evalReportTable(report).find("vkpose found by visibility: 0-20 %: 0 of 0, 20-40 %: 0 of 0, 40-60 %: 0 of 1, "
                                         "60-80 %: 0 of 0, 80-100 %: 3 of 3\n"),
            std::string::npos)
      << evalReportTable(report);
  const auto doc = nlohmann::json::parse(evalReportJson(report));
  const auto& all = doc.at("methods").at("vkpose").at("by_visibility");
  ASSERT_EQ(all.size(), 5u);
  EXPECT_EQ(all.at(4).at("instances").get<int>(), 3);
  EXPECT_EQ(all.at(4).at("found").get<int>(), 3);
  EXPECT_EQ(all.at(2).at("instances").get<int>(), 1);
  EXPECT_DOUBLE_EQ(all.at(2).at("visib_fract").at(1).get<double>(), 0.6);
  EXPECT_EQ(doc.at("methods").at("vkpose").at("objects").at("1").at("by_visibility").at(2).at("instances").get<int>(), 1);
  EXPECT_EQ(doc.at("methods").at("vkpose").at("objects").at("2").at("by_visibility").at(2).at("instances").get<int>(), 0);

  // With every instance in the top bin the line would say nothing the table does not.
  report.methods[0].by_visibility[1].instances = {0, 0, 0, 0, 3};
  EXPECT_EQ(evalReportTable(report).find("found by visibility"), std::string::npos);
}

TEST_F(MetricsMatching, UnknownObjectsAndNonRotationsAreInputErrors) {
  EXPECT_NE(test::inputErrorOf([&] { evaluateImage({est(7, 0.f, 1.f)}, {}, models); }).find("object 7"), std::string::npos);
  EXPECT_NE(test::inputErrorOf([&] { evaluateImage({}, {gt(9, 0.f)}, models); }).find("object 9"), std::string::npos);
  auto bad = est(1, 0.f, 1.f);
  bad.R(0, 0) = 3.f;
  EXPECT_NE(test::inputErrorOf([&] { evaluateImage({bad}, {gt(1, 0.f)}, models); }).find("not a rotation"), std::string::npos);
  auto nan_score = est(1, 0.f, std::nanf(""));
  EXPECT_NE(test::inputErrorOf([&] { evaluateImage({nan_score}, {gt(1, 0.f)}, models); }).find("finite"), std::string::npos);
  EXPECT_THROW(makeEvalModel(modelInfo(3, 0.1f), {}), InputError);
  EXPECT_THROW(makeEvalModel(modelInfo(3, 0.f), {Eigen::Vector3f::Zero()}), InputError);
}

TEST(Metrics, ScoresFromCounts) {
  const ObjectScores s = scoresOf({8, 1, 0});
  EXPECT_DOUBLE_EQ(s.precision, 8.0 / 9.0);
  EXPECT_DOUBLE_EQ(s.recall, 1.0);
  EXPECT_DOUBLE_EQ(s.f1, 16.0 / 17.0);
  const ObjectScores none = scoresOf({0, 0, 3});  // nothing detected: 0/0 precision is 0
  EXPECT_EQ(none.precision, 0.0);
  EXPECT_EQ(none.recall, 0.0);
  EXPECT_EQ(none.f1, 0.0);
  const EvalSummary sum = summarize({{1, {1, 0, 0}}, {2, {1, 1, 2}}});
  EXPECT_DOUBLE_EQ(sum.mean.precision, (1.0 + 0.5) / 2);
  EXPECT_DOUBLE_EQ(sum.mean.recall, (1.0 + 1.0 / 3) / 2);
  EXPECT_DOUBLE_EQ(sum.mean.f1, (1.0 + 0.4) / 2);
  EXPECT_DOUBLE_EQ(sum.total.precision, 2.0 / 3);
  EXPECT_DOUBLE_EQ(sum.total.recall, 2.0 / 4);
  EXPECT_EQ(sum.mean.tp, 2);
  EXPECT_EQ(sum.mean.fp, 1);
  EXPECT_EQ(sum.mean.fn, 2);
}

// ---------------------------------------------------------------------------------------
// The real LM-O frame

class MetricsLmo : public ::testing::Test {
 protected:
  struct Data {
    BopDataset dataset;
    std::map<int, EvalModel> models;
  };
  /// Loaded once, on first use in a test (so that a failure to load fails that test).
  static const Data& data() {
    static const Data d = [] {
      Data out{loadBopDataset(test::sharedData() + "/lmo_scene2_frame3"), {}};
      out.models = loadEvalModels(out.dataset);
      return out;
    }();
    return d;
  }
  void SetUp() override {
    VKPOSE_REQUIRE_SHARED_DATA();
    dataset = &data().dataset;
    models = &data().models;
  }

  static const BopImage& image() { return dataset->images.at(0); }
  /// The ground truth as estimates, scores falling from 1.
  static std::vector<PoseEstimate> gtEstimates() {
    std::vector<PoseEstimate> out;
    for (std::size_t i = 0; i < image().gt.size(); ++i)
      out.push_back(asEstimate(image().gt[i], 1.f - 0.1f * static_cast<float>(i)));
    return out;
  }
  static EvalSummary scored(const std::vector<PoseEstimate>& estimates, const EvalParams& params = {}) {
    std::map<int, EvalCounts> counts;
    for (const auto& [obj_id, c] : evaluateImage(estimates, image().gt, *models, params).counts) counts[obj_id] += c;
    return summarize(counts);
  }
  static std::size_t indexOf(int obj_id) {
    for (std::size_t i = 0; i < image().gt.size(); ++i)
      if (image().gt[i].obj_id == obj_id) return i;
    throw std::runtime_error("no such object");
  }

  static inline const BopDataset* dataset = nullptr;
  static inline const std::map<int, EvalModel>* models = nullptr;
};

TEST_F(MetricsLmo, GroundTruthAsEstimatesScoresPerfectly) {
  ASSERT_EQ(models->size(), 8u);
  const EvalSummary s = scored(gtEstimates());
  ASSERT_EQ(s.objects.size(), 8u);
  for (const auto& [obj_id, o] : s.objects) {
    EXPECT_EQ(o.tp, 1) << obj_id;
    EXPECT_EQ(o.fp + o.fn, 0) << obj_id;
  }
  EXPECT_EQ(s.mean.precision, 1.0);
  EXPECT_EQ(s.mean.recall, 1.0);
  EXPECT_EQ(s.mean.f1, 1.0);
  EXPECT_EQ(s.total.f1, 1.0);

  // The same through the whole-dataset path and a BOP CSV written and read back.
  std::vector<BopResult> results;
  for (const auto& e : gtEstimates()) results.push_back({2, 3, e, 0.25});
  const fs::path csv = fs::temp_directory_path() / ("vkpose_gt_results_" + std::to_string(::getpid()) + ".csv");
  saveBopResults(csv.string(), results);
  const EvalSummary again = evaluateDataset(*dataset, *models, loadBopResults(csv.string()));
  fs::remove(csv);
  EXPECT_EQ(again.mean.precision, 1.0);
  EXPECT_EQ(again.mean.recall, 1.0);
  EXPECT_EQ(again.mean.f1, 1.0);
  EXPECT_EQ(again.mean.tp, 8);

  // No estimates at all: every instance is missed.
  const EvalSummary nothing = evaluateDataset(*dataset, *models, {});
  EXPECT_EQ(nothing.mean.fn, 8);
  EXPECT_EQ(nothing.mean.recall, 0.0);
  EXPECT_NE(test::inputErrorOf([&] {
              evaluateDataset(*dataset, *models, {{2, 4, gtEstimates()[0], -1}});
            }).find("image 4"),
            std::string::npos);
}

TEST_F(MetricsLmo, DuplicateDetectionIsOneFalsePositive) {
  for (const float dup_score : {0.05f, 2.f}) {  // found after the original, or before it
    auto estimates = gtEstimates();
    const std::size_t drill = indexOf(8);
    estimates.push_back(asEstimate(image().gt[drill], dup_score));
    const auto r = evaluateImage(estimates, image().gt, *models);
    EXPECT_EQ(r.matches[dup_score < 1 ? std::size_t{8} : drill].gt, -1) << "the later of the two is the false positive";
    EXPECT_EQ(r.matches[dup_score < 1 ? drill : std::size_t{8}].gt, static_cast<int>(drill));
    const EvalSummary s = scored(estimates);
    EXPECT_EQ(s.total.tp, 8);
    EXPECT_EQ(s.total.fp, 1);
    EXPECT_EQ(s.total.fn, 0);
    EXPECT_DOUBLE_EQ(s.total.precision, 8.0 / 9.0);
    EXPECT_DOUBLE_EQ(s.total.recall, 1.0);
    EXPECT_DOUBLE_EQ(s.objects.at(8).precision, 0.5);
    EXPECT_DOUBLE_EQ(s.mean.precision, (7 + 0.5) / 8);
    EXPECT_DOUBLE_EQ(s.mean.recall, 1.0);
  }
}

TEST_F(MetricsLmo, PoseShiftedPastTheThresholdIsAFalsePositiveAndAFalseNegative) {
  const std::size_t ape = indexOf(1);
  const float d = models->at(1).info.diameter;
  const Eigen::Vector3f dir = Eigen::Vector3f(1, -2, 0.5f).normalized();
  auto near = gtEstimates(), far = gtEstimates();
  near[ape].t += 0.14f * d * dir;
  far[ape].t += 0.16f * d * dir;
  // ADD of a pure translation is its length.
  EXPECT_NEAR(poseError(models->at(1), far[ape], image().gt[ape]), 0.16f * d, 1e-6f);

  const EvalSummary ok = scored(near);
  EXPECT_EQ(ok.objects.at(1).tp, 1);
  EXPECT_EQ(ok.total.f1, 1.0);

  const EvalSummary s = scored(far);
  EXPECT_EQ(s.objects.at(1).tp, 0);
  EXPECT_EQ(s.objects.at(1).fp, 1);
  EXPECT_EQ(s.objects.at(1).fn, 1);
  EXPECT_EQ(s.objects.at(1).f1, 0.0);
  EXPECT_EQ(s.total.tp, 7);
  EXPECT_DOUBLE_EQ(s.total.precision, 7.0 / 8.0);
  EXPECT_DOUBLE_EQ(s.total.recall, 7.0 / 8.0);
  EXPECT_DOUBLE_EQ(s.mean.f1, 7.0 / 8.0);
}

TEST_F(MetricsLmo, SymmetricObjectsTurnedByTheirSymmetryNeedAdi) {
  // Eggbox (10) and glue (11) turned by the discrete symmetry models_info.json gives them (a
  // half turn about an axis through the object): ADI barely moves, ADD is large.
  const auto info =
      nlohmann::json::parse(std::ifstream(test::sharedData() + "/lmo_scene2_frame3/models/models_info.json"));
  for (const int obj_id : {10, 11}) {
    const auto& m = info[std::to_string(obj_id)]["symmetries_discrete"][0];
    Eigen::Matrix3f R_s;
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) R_s(r, c) = m[static_cast<std::size_t>(4 * r + c)].get<float>();
    const Eigen::Vector3f t_s = 0.001f * Eigen::Vector3f(m[3].get<float>(), m[7].get<float>(), m[11].get<float>());

    const std::size_t i = indexOf(obj_id);
    const GroundTruthPose& g = image().gt[i];
    auto estimates = gtEstimates();
    estimates[i].R = g.R * R_s;  // x_cam = R_g (R_s x + t_s) + t_g
    estimates[i].t = g.R * t_s + g.t;
    const EvalModel& model = models->at(obj_id);
    const float d = model.info.diameter;
    const float adi = poseError(model, estimates[i], g, PoseErrorType::ADI);
    const float add = poseError(model, estimates[i], g, PoseErrorType::ADD);
    EXPECT_LT(adi, 0.02f * d) << obj_id;
    EXPECT_GT(add, 0.25f * d) << obj_id;  // well past the 0.15 d threshold
    EXPECT_EQ(poseError(model, estimates[i], g), adi) << "symmetric: ADI by default";

    EXPECT_EQ(scored(estimates).total.f1, 1.0) << obj_id;
    EvalParams add_only;
    add_only.error = PoseErrorType::ADD;
    const EvalSummary s = scored(estimates, add_only);
    EXPECT_EQ(s.objects.at(obj_id).fp, 1) << obj_id;
    EXPECT_EQ(s.objects.at(obj_id).fn, 1) << obj_id;
    EXPECT_EQ(s.total.tp, 7) << obj_id;
  }
}

// ---------------------------------------------------------------------------------------
// BOP results CSV

fs::path tempCsv(const char* name) {
  return fs::temp_directory_path() / (std::string("vkpose_") + name + "_" + std::to_string(::getpid()) + ".csv");
}

std::string fileText(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

TEST(Metrics, BopCsvRoundTripsExactly) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u(-1.f, 1.f);
  std::vector<BopResult> results;
  for (int i = 0; i < 200; ++i) {
    BopResult r;
    r.scene_id = i / 50;
    r.im_id = i / 7;
    r.estimate.obj_id = 1 + i % 15;
    r.estimate.score = i % 10 == 0 ? 1.f : std::abs(u(rng)) * std::pow(10.f, static_cast<float>(i % 7 - 3));
    r.estimate.R = Eigen::Quaternionf(u(rng), u(rng), u(rng), u(rng)).normalized().toRotationMatrix();
    r.estimate.t = Eigen::Vector3f(0.3f * u(rng), 0.3f * u(rng), 1.f + u(rng));
    if (i == 1) r.estimate.t = Eigen::Vector3f(1e-9f, -0.f, 123.456f);
    r.time_s = i % 3 == 0 ? -1.0 : 0.001 * i + 1e-7;
    results.push_back(r);
  }
  const fs::path p = tempCsv("roundtrip");
  saveBopResults(p.string(), results);
  const std::string text = fileText(p);
  const auto loaded = loadBopResults(p.string());
  fs::remove(p);

  EXPECT_EQ(text.substr(0, text.find('\n')), "scene_id,im_id,obj_id,score,R,t,time");
  ASSERT_EQ(loaded.size(), results.size());
  for (std::size_t i = 0; i < results.size(); ++i) {
    EXPECT_EQ(loaded[i].scene_id, results[i].scene_id) << i;
    EXPECT_EQ(loaded[i].im_id, results[i].im_id) << i;
    EXPECT_EQ(loaded[i].estimate.obj_id, results[i].estimate.obj_id) << i;
    EXPECT_EQ(loaded[i].estimate.score, results[i].estimate.score) << i;
    EXPECT_EQ(loaded[i].estimate.R, results[i].estimate.R) << i;
    EXPECT_EQ(loaded[i].estimate.t, results[i].estimate.t) << i;
    EXPECT_EQ(loaded[i].time_s, results[i].time_s) << i;
  }
}

TEST(Metrics, BopCsvLinesAreBopToolkits) {
  BopResult r;
  r.scene_id = 2;
  r.im_id = 3;
  r.estimate = {5, 0.5f, Eigen::Matrix3f::Identity(), Eigen::Vector3f(0.25f, -0.5f, 1.f)};
  const fs::path p = tempCsv("format");
  saveBopResults(p.string(), {r});
  EXPECT_EQ(fileText(p), "scene_id,im_id,obj_id,score,R,t,time\n2,3,5,0.5,1 0 0 0 1 0 0 0 1,250 -500 1000,-1\n");

  // What bop_toolkit's Python writes (no header needed, Python's float text, CRLF too) reads.
  std::ofstream(p) << "1,12,8,0.87,0.0 -1.0 0.0 1.0 0.0 0.0 0.0 0.0 1.0,161.68945982 -113.74 1.1e3,0.031\r\n\n";
  const auto loaded = loadBopResults(p.string());
  ASSERT_EQ(loaded.size(), 1u);
  EXPECT_EQ(loaded[0].im_id, 12);
  EXPECT_FLOAT_EQ(loaded[0].estimate.R(0, 1), -1.f);
  EXPECT_FLOAT_EQ(loaded[0].estimate.R(1, 0), 1.f);
  EXPECT_FLOAT_EQ(loaded[0].estimate.t.x(), 0.16168945982f);
  EXPECT_FLOAT_EQ(loaded[0].estimate.t.z(), 1.1f);
  EXPECT_DOUBLE_EQ(loaded[0].time_s, 0.031);

  const std::string good = "0,3,5,0.5,1 0 0 0 1 0 0 0 1,1 2 1000,-1";
  const auto check = [&](const std::string& bad_line, std::initializer_list<std::string> parts) {
    std::ofstream(p) << "scene_id,im_id,obj_id,score,R,t,time\n" << good << '\n' << bad_line << '\n';
    const std::string msg = test::inputErrorOf([&] { loadBopResults(p.string()); });
    for (const auto& part : parts) EXPECT_NE(msg.find(part), std::string::npos) << part << " missing from: " << msg;
  };
  check("0,3,5,0.5,1 0 0 0 1 0 0 0 1,1 2 1000", {p.filename().string(), "line 3", "6 comma-separated columns"});
  check("0,3,5,0.5,1 0 0 0 1 0 0 0,1 2 1000,-1", {"line 3", "'R'", "8 numbers"});
  check("0,3,5,high,1 0 0 0 1 0 0 0 1,1 2 1000,-1", {"line 3", "'score'", "'high'"});
  check("0,3,5,nan,1 0 0 0 1 0 0 0 1,1 2 1000,-1", {"line 3", "'score'", "finite"});
  check("-1,3,5,0.5,1 0 0 0 1 0 0 0 1,1 2 1000,-1", {"line 3", "'scene_id'"});
  check("0,3,5,0.5,2 0 0 0 1 0 0 0 1,1 2 1000,-1", {"line 3", "not a rotation"});
  check("0,3,5,0.5,1 0 0 0 1 0 0 0 1,1 x 1000,-1", {"line 3", "'t'"});
  check("0,3,5,0.5,1 0 0 0 1 0 0 0 1,1 2 1000,", {"line 3", "'time'"});
  fs::remove(p);
  EXPECT_NE(test::inputErrorOf([&] { loadBopResults(p.string()); }).find("cannot open"), std::string::npos);
}

}  // namespace
}  // namespace vkpose

namespace vkpose {
namespace {

TEST(PrecisionRecall, OnePointPerScoreFromTheTopIgnoredLeftOut) {
  const std::vector<ScoredOutcome> outcomes{{1, 0.9f, true, false},  {1, 0.8f, false, false}, {1, 0.7f, true, false},
                                            {1, 0.7f, false, false}, {1, 0.4f, true, false},  {1, 0.3f, true, true},
                                            {2, 0.95f, false, false}};
  const auto curve = precisionRecallCurve(outcomes, 4, 1);
  ASSERT_EQ(curve.size(), 4u);
  EXPECT_FLOAT_EQ(curve[0].threshold, 0.9f);
  EXPECT_DOUBLE_EQ(curve[0].scores.precision, 1.0);
  EXPECT_DOUBLE_EQ(curve[0].scores.recall, 0.25);
  EXPECT_DOUBLE_EQ(curve[1].scores.precision, 0.5);
  // Both estimates of score 0.7 are in the third point.
  EXPECT_FLOAT_EQ(curve[2].threshold, 0.7f);
  EXPECT_EQ(curve[2].scores.tp, 2);
  EXPECT_EQ(curve[2].scores.fp, 2);
  EXPECT_EQ(curve[2].scores.fn, 2);
  EXPECT_DOUBLE_EQ(curve[3].scores.precision, 0.6);
  EXPECT_DOUBLE_EQ(curve[3].scores.recall, 0.75);
  // All objects: object 2's false positive comes first.
  const auto all = precisionRecallCurve(outcomes, 5);
  ASSERT_EQ(all.size(), 5u);
  EXPECT_DOUBLE_EQ(all[0].scores.precision, 0.0);
  EXPECT_EQ(all.back().scores.fp, 3);
  EXPECT_TRUE(precisionRecallCurve({}, 3).empty());
}

TEST(PrecisionRecall, ThePlotShowsEachMethodsFiguresAtHalf) {
  EvalReport report;
  report.dataset = "stress";
  report.split = "test";
  MethodEvaluation m;
  m.outcomes = {{1, 0.9f, true, false}, {1, 0.6f, true, false}, {1, 0.55f, false, false}, {1, 0.3f, false, false}};
  m.summary.total.tp = 2;
  m.summary.total.fn = 2;
  report.methods.push_back(m);
  m.method = EvalMethod::Linemod;
  m.outcomes = {{1, 0.4f, true, false}};
  report.methods.push_back(m);
  const std::string svg = precisionRecallSvg(report);
  EXPECT_EQ(svg.rfind("<svg", 0), 0u);
  EXPECT_NE(svg.find("</svg>"), std::string::npos);
  // At 0.5: the three estimates from 0.55 up, two right, of four instances.
  EXPECT_NE(svg.find("at 0.5: P 0.667 R 0.500"), std::string::npos) << svg;
  EXPECT_NE(svg.find("nothing scores 0.5"), std::string::npos);  // linemod's only estimate scores 0.4
  EXPECT_EQ(std::count(svg.begin(), svg.end(), '\n') > 20, true);
}

}  // namespace
}  // namespace vkpose
