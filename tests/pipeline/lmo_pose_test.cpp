// Stages 1-8 on the real LM-O frame (scene 2, image 3): banks for its 8 objects, detection,
// refined and verified poses scored against scene_gt.json with ADD/ADI at 0.15 d, object by
// object; then the same frame without its depth image (colour only), scored by proj2d.
#include <cstdio>
#include <map>

#include <gtest/gtest.h>

#include "hypotheses/cluster_score.hpp"
#include "test_support.hpp"
#include "vkpose/bank.hpp"
#include "vkpose/detector.hpp"
#include "vkpose/evaluation.hpp"
#include "vkpose/frame.hpp"
#include "vkpose/geometry.hpp"

namespace vkpose {
namespace {

const BopDataset& lmo() {
  static const BopDataset dataset = loadBopDataset(test::sharedData() + "/lmo_scene2_frame3");
  return dataset;
}

/// What `vkpose train --camera camera.json --radii 0.9:1.3:0.1` makes for each object: the
/// LM-O objects stand 0.95-1.27 m from the camera, viewed from above.
const std::vector<TemplateBank>& lmoBanks() {
  static const std::vector<TemplateBank> banks = [] {
    std::vector<TemplateBank> out;
    for (const auto& [id, info] : lmo().models) {
      TrainingParams params;
      params.camera = lmo().camera;
      params.views.radii = {0.9f, 1.3f, 0.1f};
      params.symmetric = info.symmetric;
      const Mesh mesh = loadMesh(lmo().modelPath(id), MeshUnits::Millimetres);
      out.push_back(test::cachedBank(mesh, params));
    }
    return out;
  }();
  return banks;
}

int objectId(const std::string& name) { return std::stoi(name.substr(name.find('_') + 1)); }

struct LmoRun {
  DetectionResult result;
  /// Per detection: the pose error against the nearest instance of its object, in diameters
  /// (ADD, or ADI for symmetric objects); a large value when the frame has no such object.
  std::vector<float> errors;
};

LmoRun lmoRun() {
  const BopImage& image = lmo().images.at(0);
  const LinemodFrame frame = loadFrame(image.rgb_path, image.depth_path, image.camera.depth_scale);
  Detector detector(test::context(), lmoBanks());
  LmoRun r;
  r.result = detector.detect(frame, image.camera);
  const std::map<int, EvalModel> models = loadEvalModels(lmo());
  for (const Detection& d : r.result.detections) {
    const int id = objectId(d.object);
    float best = 1e9f;
    for (const GroundTruthPose& gt : image.gt)
      if (gt.obj_id == id) {
        const EvalModel& m = models.at(id);
        best = std::min(best, poseError(m, {id, d.score, d.pose.R, d.pose.t}, gt) / m.info.diameter);
      }
    r.errors.push_back(best);
    std::printf("  %s: score %.3f, phi %.2f, error %.3f d\n", d.object.c_str(), d.score, d.collision_rate, best);
  }
  return r;
}

/// The same frame with its depth image withheld: colour-only detection (docs/colour_only.md),
/// scored by the mean 2D projection error of the model points (proj2d, 5 px).
void checkColourOnly() {
  const BopImage& image = lmo().images.at(0);
  const LinemodFrame frame = loadFrame(image.rgb_path, "", image.camera.depth_scale);
  ASSERT_TRUE(frame.depth_mm.empty());
  Detector detector(test::context(), lmoBanks());
  const DetectionResult result = detector.detect(frame, image.camera);
  const std::map<int, EvalModel> models = loadEvalModels(lmo());
  // Each object's best proj2d among the detections and the rejected poses: what the fit
  // reached, and what verification kept.
  std::map<int, float> reached, kept;
  auto score = [&](const std::vector<Detection>& ds, std::map<int, float>& best) {
    for (const Detection& d : ds) {
      const int id = objectId(d.object);
      EXPECT_TRUE(d.colour_only) << d.object;
      for (const GroundTruthPose& gt : image.gt)
        if (gt.obj_id == id) {
          const float e = poseError(models.at(id), {id, d.score, d.pose.R, d.pose.t}, gt, PoseErrorType::Proj2D,
                                    &image.camera);
          best.emplace(id, e);
          best[id] = std::min(best[id], e);
        }
    }
  };
  score(result.detections, kept);
  score(result.detections, reached);
  score(result.rejected, reached);
  int within = 0;
  for (const auto& [id, e] : kept) {
    std::printf("  obj %d: kept, proj2d %.1f px\n", id, e);
    within += e < 5.f;
  }
  // Issue 50: nothing wrong at score 0.5 or more. And the colour test (colour_only.
  // min_colour_agreement 0.2) keeps the wrong poses few: 16 today, 33 without it.
  int wrong = 0;
  for (const Detection& d : result.detections) {
    const int id = objectId(d.object);
    float e = 1e9f;
    for (const GroundTruthPose& gt : image.gt)
      if (gt.obj_id == id)
        e = std::min(e, poseError(models.at(id), {id, d.score, d.pose.R, d.pose.t}, gt, PoseErrorType::Proj2D,
                                  &image.camera));
    wrong += e >= 5.f;
    if (d.score >= 0.5f) {
      EXPECT_LT(e, 5.f) << d.object << " at score " << d.score << " is " << e << " px off";
    }
  }
  EXPECT_LE(wrong, 20);
  // The can (5), cat (6) and duck (9) are found within 5 px and kept. The goal is 5 of the 8
  // (issue 50); the driller, glue and holepuncher get no start close enough to fit from yet.
  for (int id : {5, 6, 9}) {
    ASSERT_TRUE(reached.count(id)) << "object " << id << " got no pose";
    EXPECT_LT(reached[id], 5.f) << "object " << id;
  }
  EXPECT_GE(within, 3);
  std::vector<std::string> stages;
  for (const auto& [name, ms] : result.timings_ms) stages.push_back(name);
  for (const char* s : {"edges", "contour_fit", "verification"})
    EXPECT_NE(std::find(stages.begin(), stages.end(), s), stages.end()) << s;
}

// One test, not three: ctest runs each test in its own process, and each would train the 8
// banks (about a minute each on 2 cores) when the cache is cold.
TEST(LmoPose, FindsTheVisibleObjectsWithDepthAndTheClearOnesWithout) {
  VKPOSE_REQUIRE_SHARED_DATA();
  const LmoRun run = lmoRun();
  // Visible fractions: can (5) 0.96, cat (6) 0.99, driller (8) 0.97, duck (9) 0.96, glue (11)
  // 0.80, holepuncher (12) 0.96; eggbox (10) is half hidden, ape (1) 80 % hidden.
  for (int id : {5, 6, 8, 9, 11, 12}) {
    bool correct = false;
    for (std::size_t i = 0; i < run.errors.size(); ++i)
      correct |= objectId(run.result.detections[i].object) == id && run.errors[i] < 0.15f;
    EXPECT_TRUE(correct) << "object " << id << " has no detection with a pose within 0.15 d";
  }
  // No wrong detection: every reported pose is within 0.15 d of an instance of its object.
  for (std::size_t i = 0; i < run.errors.size(); ++i)
    EXPECT_LT(run.errors[i], 0.15f) << run.result.detections[i].object << " at " << run.result.detections[i].x << ","
                                    << run.result.detections[i].y << " is wrong by " << run.errors[i] << " d";
  // The first fit stops most starts before MLS and ICP: 14 refined for 6 detections today, 359
  // without it; issue 48 asks for at most 2.5 a detection.
  EXPECT_LE(static_cast<double>(run.result.refined_candidates), 2.5 * static_cast<double>(run.errors.size()));
  // Every pose stage is timed.
  std::vector<std::string> stages;
  for (const auto& [name, ms] : run.result.timings_ms) stages.push_back(name);
  for (const char* s : {"initial_pose", "mls", "icp", "verification"})
    EXPECT_NE(std::find(stages.begin(), stages.end(), s), stages.end()) << s;
  // Without depth, from the same banks (in this process: they train once when the cache is cold).
  checkColourOnly();
}


}  // namespace
}  // namespace vkpose
