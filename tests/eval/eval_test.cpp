// The baselines and `vkpose eval` on the real LM-O frame: PPF finds a mostly visible object,
// LINEMOD-alone poses sit where their matches are, and the evaluation reports all three
// methods with scores in [0, 1].
#include <filesystem>
#include <limits>

#include <unistd.h>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "eval/baselines.hpp"
#include "hypotheses/cluster_score.hpp"
#include "match/features.hpp"
#include "match/matcher.hpp"
#include "test_support.hpp"
#include "vkpose/bank.hpp"
#include "vkpose/detector.hpp"
#include "vkpose/error.hpp"
#include "vkpose/evaluation.hpp"
#include "vkpose/frame.hpp"
#include "vkpose/geometry.hpp"

namespace vkpose {
namespace {

std::string lmoRoot() { return test::sharedData() + "/lmo_scene2_frame3"; }

// ---------------------------------------------------------------------------------------
// Fixtures: the LM-O frame and a coarse full-sphere bank of its driller (obj 8)

constexpr int kDriller = 8;

struct LmoData {
  BopDataset dataset;
  std::map<int, EvalModel> models;
  LinemodFrame frame;
  const BopImage& image() const { return dataset.images.front(); }
  const GroundTruthPose& gt(int obj_id) const {
    for (const auto& g : image().gt)
      if (g.obj_id == obj_id) return g;
    throw InputError("no ground truth");
  }
};

const LmoData& lmo() {
  static const LmoData d = [] {
    LmoData out;
    out.dataset = loadBopDataset(lmoRoot());
    out.models = loadEvalModels(out.dataset);
    const BopImage& im = out.dataset.images.front();
    out.frame = loadFrame(im.rgb_path, im.depth_path, im.camera.depth_scale);
    return out;
  }();
  return d;
}

/// A coarse sampling of the full view sphere (120 viewpoints, 3 distances around the frame's
/// 1 m, 7 in-plane rotations: 2,520 views), for the LM-O camera; cached between runs.
const TemplateBank& drillerBank() {
  static const TemplateBank bank = [] {
    TrainingParams params;
    params.views.viewpoints = 120;
    params.views.full_sphere = true;
    params.views.radii = {0.9f, 1.1f, 0.1f};
    params.views.inplane_deg = {-45.f, 45.f, 15.f};
    params.camera = loadCamera(lmoRoot() + "/camera.json");
    return test::cachedBank(loadMesh(lmo().dataset.modelPath(kDriller), MeshUnits::Millimetres), params);
  }();
  return bank;
}

float errorOf(int obj_id, const Pose& pose) {
  return poseError(lmo().models.at(obj_id), {obj_id, 1.f, pose.R, pose.t}, lmo().gt(obj_id));
}

// ---------------------------------------------------------------------------------------
// PPF

TEST(PpfBaseline, SamplesTheMeshSurfaceWithOutwardNormals) {
  Mesh cube;  // the unit cube, corners at 0 and 1
  for (int i = 0; i < 8; ++i) cube.vertices.emplace_back(i & 1, (i >> 1) & 1, (i >> 2) & 1);
  cube.faces = {{0, 2, 1}, {1, 2, 3}, {4, 5, 6}, {5, 7, 6}, {0, 1, 4}, {1, 5, 4},
                {2, 6, 3}, {3, 6, 7}, {0, 4, 2}, {2, 4, 6}, {1, 3, 5}, {3, 7, 5}};
  finishMesh(cube);
  const cv::Mat pc = sampleMeshSurface(cube, 3000);
  ASSERT_EQ(pc.rows, 3000);
  ASSERT_EQ(pc.cols, 6);
  int on_top = 0;
  for (int i = 0; i < pc.rows; ++i) {
    const float* r = pc.ptr<float>(i);
    const Eigen::Vector3f p(r[0], r[1], r[2]), n(r[3], r[4], r[5]);
    EXPECT_NEAR(n.norm(), 1.f, 1e-5f);
    // On the surface, normals pointing away from the centre.
    EXPECT_NEAR((p - Eigen::Vector3f::Constant(0.5f)).cwiseAbs().maxCoeff(), 0.5f, 1e-5f);
    EXPECT_GT(n.dot(p - Eigen::Vector3f::Constant(0.5f)), 0.f);
    on_top += r[2] > 1.f - 1e-5f;
  }
  EXPECT_NEAR(on_top, 500, 80);  // one face of six, area-weighted
  EXPECT_EQ(cv::norm(pc, sampleMeshSurface(cube, 3000), cv::NORM_INF), 0.0);  // deterministic
}

TEST(PpfBaseline, RejectsBadParametersAndObjectsAddedTwice) {
  PpfParams p;
  p.model_step = 0.f;
  EXPECT_NE(test::inputErrorOf([&] { validatePpfParams(p); }).find("model step"), std::string::npos);
  p = {};
  p.max_poses = 0;
  EXPECT_THROW(PpfBaseline{p}, InputError);
  VKPOSE_REQUIRE_SHARED_DATA();
  PpfBaseline ppf;
  const Mesh mesh = loadMesh(lmo().dataset.modelPath(1), MeshUnits::Millimetres);
  ppf.addObject(1, mesh);
  EXPECT_NE(test::inputErrorOf([&] { ppf.addObject(1, mesh); }).find("object 1"), std::string::npos);
  EXPECT_THROW(ppf.detect(cv::Mat(), lmo().image().camera), InputError);
  EXPECT_THROW(ppf.detect(cv::Mat(4, 4, CV_32F), lmo().image().camera), InputError);
  // A depth image with nothing in it gives nothing, not a crash.
  EXPECT_TRUE(ppf.detect(cv::Mat(480, 640, CV_16UC1, cv::Scalar(0)), lmo().image().camera).detections.empty());
}

TEST(PpfBaseline, FindsTheDrillerOnTheLmoFrame) {
  VKPOSE_REQUIRE_SHARED_DATA();
  PpfBaseline ppf;
  ppf.addObject(kDriller, loadMesh(lmo().dataset.modelPath(kDriller), MeshUnits::Millimetres));
  const PpfResult r = ppf.detect(lmo().frame.depth_mm, lmo().image().camera);
  ASSERT_FALSE(r.detections.empty());
  EXPECT_LE(r.detections.size(), static_cast<std::size_t>(PpfParams{}.max_poses));
  EXPECT_GT(r.scene_points, 10000u);
  EXPECT_GT(r.object_ms.at(kDriller), 0.0);
  // One of the best-voted poses is the driller (97% visible): measured ADD 0.08 d (21 mm).
  const float d = lmo().dataset.models.at(kDriller).diameter;
  float best = std::numeric_limits<float>::infinity();
  for (const auto& det : r.detections) best = std::min(best, errorOf(kDriller, det.pose));
  EXPECT_LT(best, 0.15f * d);
  for (std::size_t i = 1; i < r.detections.size(); ++i)
    EXPECT_GE(r.detections[i - 1].score, r.detections[i].score);
}

// ---------------------------------------------------------------------------------------
// LINEMOD alone

TEST(LinemodBaseline, ReportsEveryMatchWithAPoseThatProjectsOntoIt) {
  VKPOSE_REQUIRE_SHARED_DATA();
  const TemplateBank& bank = drillerBank();
  const Camera& camera = lmo().image().camera;
  for (bool offset : {false, true}) {
    LinemodBaselineParams params;
    params.depth_offset = offset;
    params.max_per_object = 0;  // all
    LinemodBaseline baseline(test::context(), {bank}, params);
    const DetectionResult r = baseline.detect(lmo().frame, camera);
    ASSERT_GT(r.detections.size(), 10u) << "offset " << offset;
    EXPECT_EQ(r.detections.size(), r.matches);
    for (std::size_t i = 0; i < r.detections.size(); ++i) {
      const Detection& d = r.detections[i];
      const BankTemplate& t = bank.templates.at(static_cast<std::size_t>(d.template_index));
      EXPECT_FLOAT_EQ(d.score, d.similarity / 100.f);
      EXPECT_GE(d.similarity, params.match.threshold);
      if (i > 0) {
        EXPECT_GE(r.detections[i - 1].score, d.score);
      }
      // The object's centre projects where the match put it; the rotation is the template's
      // turned onto that viewing ray, the distance the template's (plus the depth offset).
      const Eigen::Vector3f centre = d.pose.R * bank.centre + d.pose.t;
      const Eigen::Vector2f px = camera.project(centre);
      ASSERT_NEAR(px.x(), d.x, 0.05f) << i;
      ASSERT_NEAR(px.y(), d.y, 0.05f) << i;
      if (!offset) {
        EXPECT_NEAR(centre.norm(), (t.pose.R * bank.centre + t.pose.t).norm(), 1e-4f) << i;
      }
      EXPECT_NEAR((d.pose.R.transpose() * d.pose.R - Eigen::Matrix3f::Identity()).norm(), 0.f, 1e-4f);
    }
  }
}

TEST(LinemodBaseline, KeepsTheBestMatchesOfEachObject) {
  VKPOSE_REQUIRE_SHARED_DATA();
  const TemplateBank& bank = drillerBank();
  const Camera& camera = lmo().image().camera;
  LinemodBaselineParams all;
  all.depth_offset = false;
  all.max_per_object = 0;
  const DetectionResult every = LinemodBaseline(test::context(), {bank}, all).detect(lmo().frame, camera);
  constexpr int kCap = 7;
  ASSERT_GT(every.detections.size(), static_cast<std::size_t>(kCap));
  // The same bank as two objects: each keeps its own best kCap.
  LinemodBaselineParams capped = all;
  capped.max_per_object = kCap;
  const DetectionResult r = LinemodBaseline(test::context(), {bank, bank}, capped).detect(lmo().frame, camera);
  EXPECT_EQ(r.matches, 2 * every.matches);  // the raw count stays
  ASSERT_EQ(r.detections.size(), static_cast<std::size_t>(2 * kCap));
  for (int b = 0; b < 2; ++b) {
    std::vector<float> scores;
    for (const Detection& d : r.detections)
      if (d.bank == b) scores.push_back(d.similarity);
    ASSERT_EQ(scores.size(), static_cast<std::size_t>(kCap)) << "bank " << b;
    for (int i = 0; i < kCap; ++i) EXPECT_FLOAT_EQ(scores[static_cast<std::size_t>(i)], every.detections[static_cast<std::size_t>(i)].similarity);
  }
  capped.max_per_object = -1;
  EXPECT_NE(test::inputErrorOf([&] { LinemodBaseline(test::context(), {bank}, capped); }).find("per object"),
            std::string::npos);
}

// ---------------------------------------------------------------------------------------
// The evaluation

TEST(Evaluation, ParsesMethodsAndNamesResultFiles) {
  EXPECT_EQ(parseEvalMethod("ppf"), EvalMethod::Ppf);
  EXPECT_EQ(methodName(parseEvalMethod("linemod")), "linemod");
  EXPECT_NE(test::inputErrorOf([] { parseEvalMethod("drost"); }).find("vkpose, linemod and ppf"), std::string::npos);
  EXPECT_EQ(methodResultsPath("out/lmo-test.csv", EvalMethod::Vkpose), "out/vkpose_lmo-test.csv");
  EXPECT_EQ(methodResultsPath("lmo-test.csv", EvalMethod::Ppf), "ppf_lmo-test.csv");
}

TEST(Evaluation, RefusesBanksTheDatasetHasNoObjectFor) {
  VKPOSE_REQUIRE_SHARED_DATA();
  TemplateBank bank;
  bank.object = "obj_000002";
  bank.diameter = 0.2f;
  EXPECT_NE(test::inputErrorOf([&] { checkBanksAgainstDataset({{2, bank}}, lmo().dataset); }).find("object 2"),
            std::string::npos);
  bank.diameter = 0.0261f;  // the driller read in the wrong units
  EXPECT_NE(test::inputErrorOf([&] { checkBanksAgainstDataset({{kDriller, bank}}, lmo().dataset); }).find("units"),
            std::string::npos);
  EvalRunParams params;
  params.methods = {EvalMethod::Vkpose};
  EXPECT_NE(test::inputErrorOf([&] { runEvaluation(test::context(), lmo().dataset, {}, params); }).find("--bank"),
            std::string::npos);
  params.methods = {EvalMethod::Ppf, EvalMethod::Ppf};
  EXPECT_NE(test::inputErrorOf([&] { runEvaluation(test::context(), lmo().dataset, {}, params); }).find("twice"),
            std::string::npos);
}

TEST(Evaluation, WarnsOfInstancesOutsideTheDistancesTheBankWasTrainedAt) {
  TemplateBank bank;  // default radii 0.6:1:0.1 m: found at 0.55-1.05 m
  bank.object = "cup";
  bank.centre = {0.f, 0.f, 0.05f};
  EXPECT_FLOAT_EQ(coveredDistances(bank.params.views.radii).first, 0.55f);
  EXPECT_FLOAT_EQ(coveredDistances(bank.params.views.radii).second, 1.05f);
  auto at = [](int obj_id, float z, float visib) {
    GroundTruthPose g;
    g.obj_id = obj_id;
    g.t = {0.f, 0.f, z - 0.05f};  // the centre, 5 cm up the object's z, at z
    g.visib_fract = visib;
    return g;
  };
  BopDataset dataset;
  dataset.images.resize(3);
  dataset.images[0].gt = {at(1, 0.5f, 1.f), at(1, 0.8f, 1.f), at(2, 3.f, 1.f)};
  dataset.images[1].gt = {at(1, 1.2f, 0.9f), at(1, 0.4f, 0.3f)};
  dataset.images[2].gt = {at(1, 2.f, 1.f)};
  const std::map<int, TemplateBank> banks{{1, bank}};
  // Images 0-1, instances at least half visible: 0.5 m and 1.2 m of three lie outside; object 2
  // has no bank; the 0.4 m one is under the visibility asked for.
  const std::vector<std::string> w = distanceCoverageWarnings(banks, dataset, 0, 2, 0.5f);
  ASSERT_EQ(w.size(), 1u);
  EXPECT_NE(w[0].find("2 of 3 instances of object 1"), std::string::npos) << w[0];
  EXPECT_NE(w[0].find("1 nearer (down to 0.50 m), 1 farther (up to 1.20 m)"), std::string::npos) << w[0];
  EXPECT_NE(w[0].find("0.55-1.05 m"), std::string::npos) << w[0];
  EXPECT_TRUE(distanceCoverageWarnings(banks, dataset, 0, 1, 0.f).size() == 1u);
  // Every instance inside: no warning; a range past the images is clipped.
  dataset.images[0].gt = {at(1, 0.6f, 1.f), at(1, 1.f, 1.f)};
  EXPECT_TRUE(distanceCoverageWarnings(banks, dataset, 0, 1, 0.f).empty());
  EXPECT_EQ(distanceCoverageWarnings(banks, dataset, 0, 99, 0.f).size(), 1u);  // image 2's 2 m
  // The report JSON carries them too, for scripts that read `eval --report`.
  EvalReport report;
  report.warnings = w;
  EXPECT_EQ(nlohmann::json::parse(evalReportJson(report)).at("warnings").get<std::vector<std::string>>(), w);
}

TEST(Evaluation, ReportsTheThreeMethodsOnTheLmoFrame) {
  VKPOSE_REQUIRE_SHARED_DATA();
  EvalRunParams params;
  std::size_t steps = 0, total = 0;
  const EvalReport report = runEvaluation(test::context(), lmo().dataset, {{kDriller, drillerBank()}}, params,
                                          [&](std::size_t done, std::size_t all) { steps = done, total = all; });
  EXPECT_EQ(steps, 3u);
  EXPECT_EQ(total, 3u);
  EXPECT_EQ(report.images, 1);
  EXPECT_EQ(report.objects, std::vector<int>{kDriller});
  ASSERT_EQ(report.methods.size(), 3u);

  const auto doc = nlohmann::json::parse(evalReportJson(report));
  ASSERT_EQ(doc.at("methods").size(), 3u);
  for (const char* method : {"vkpose", "linemod", "ppf"}) {
    const auto& m = doc.at("methods").at(method);
    const auto& avg = m.at("average");
    ASSERT_EQ(avg.size(), 4u) << method;
    for (const char* key : {"precision", "recall", "f1"}) {
      EXPECT_GE(avg.at(key).get<double>(), 0.0) << method << " " << key;
      EXPECT_LE(avg.at(key).get<double>(), 1.0) << method << " " << key;
    }
    EXPECT_GT(avg.at("ms_per_image").get<double>(), 0.0) << method;
    ASSERT_EQ(m.at("objects").size(), 1u) << method;
    const auto& o = m.at("objects").at("8");
    EXPECT_EQ(o.at("tp").get<int>() + o.at("fn").get<int>(), 1) << method;  // one driller in the frame
    // The driller is 97 % visible: the top bin holds it, found when it is a true positive.
    for (const auto* bins : {&o.at("by_visibility"), &m.at("by_visibility")}) {
      ASSERT_EQ(bins->size(), 5u) << method;
      EXPECT_EQ(bins->at(4).at("instances").get<int>(), 1) << method;
      EXPECT_EQ(bins->at(4).at("found").get<int>(), o.at("tp").get<int>()) << method;
      EXPECT_DOUBLE_EQ(bins->at(4).at("visib_fract").at(0).get<double>(), 0.8) << method;
      EXPECT_EQ(bins->at(0).at("instances").get<int>(), 0) << method;
    }
  }
  // LINEMOD alone reports every match: far more estimates than instances.
  const auto& linemod = doc.at("methods").at("linemod").at("objects").at("8");
  EXPECT_GT(linemod.at("fp").get<int>(), 10);
  // ppf finds the driller (the test above).
  EXPECT_EQ(doc.at("methods").at("ppf").at("objects").at("8").at("tp").get<int>(), 1);

  // The results CSV of each method reads back.
  const auto dir = std::filesystem::temp_directory_path() / ("vkpose_eval_test_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  for (const MethodEvaluation& m : report.methods) {
    const std::string path = methodResultsPath((dir / "lmo-test.csv").string(), m.method);
    saveBopResults(path, m.results);
    EXPECT_EQ(loadBopResults(path).size(), m.results.size());
  }
  std::filesystem::remove_all(dir);
  EXPECT_NE(evalReportTable(report).find("average"), std::string::npos);
  // Every instance is in the top bin, so the table has no line of found by visibility.
  EXPECT_EQ(evalReportTable(report).find("found by visibility"), std::string::npos);
}

}  // namespace
}  // namespace vkpose
