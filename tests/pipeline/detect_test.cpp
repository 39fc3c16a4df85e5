// `vkpose detect` end to end on the real IC-BIN cup frame, and the detection JSON's fields.
#include <algorithm>
#include <filesystem>

#include <unistd.h>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>
#include <nlohmann/json.hpp>

#include "hypotheses/cluster_score.hpp"
#include "match/matcher.hpp"
#include "test_support.hpp"
#include "vkpose/bank.hpp"
#include "vkpose/detector.hpp"
#include "vkpose/device.hpp"
#include "vkpose/error.hpp"
#include "vkpose/frame.hpp"
#include "vkpose/geometry.hpp"

namespace vkpose {
namespace {

/// The default bank of the coffee cup for the IC-BIN camera (what `vkpose train` makes),
/// cached in the build folder between runs: training takes most of a minute on 2 cores.
const TemplateBank& icbinCupBank() {
  static const TemplateBank bank = [] {
    TrainingParams params;
    params.camera = loadCamera(test::sharedData() + "/icbin/camera.json");
    params.symmetric = true;
    return test::cachedBank(loadMesh(test::sharedData() + "/meshes/coffee_cup.stl"), params);
  }();
  return bank;
}

struct IcbinResult {
  DetectionResult result;
  std::string json;
};

IcbinResult detectIcbinScene2(bool poses, unsigned threads = 0, bool first_fit = true) {
  const std::string d = test::sharedData() + "/icbin/";
  const Camera camera = loadCamera(d + "camera.json");
  const LinemodFrame frame = loadFrame(d + "scene2/rgb/0000.png", d + "scene2/depth/0000.png", camera.depth_scale);
  DetectorParams params;
  params.estimate_poses = poses;
  params.threads = threads;
  params.refine.first_fit = first_fit;
  Detector detector(test::context(), {icbinCupBank()}, params);
  IcbinResult out;
  out.result = detector.detect(frame, camera);
  out.json = detectionJson(out.result, {"rgb.png", "depth.png", test::context().device().name});
  return out;
}

/// Stages 1-5 only (--no-pose): the hypotheses.
const IcbinResult& icbinScene2() {
  static const IcbinResult r = detectIcbinScene2(false);
  return r;
}

/// Stages 1-8: refined and verified poses.
const IcbinResult& icbinScene2Poses() {
  static const IcbinResult r = detectIcbinScene2(true);
  return r;
}

TEST(DetectIcbin, FindsTheCupsOncePerCupAndNothingOnTheTableOrMarkers) {
  VKPOSE_REQUIRE_SHARED_DATA();
  const auto& dets = icbinScene2().result.detections;
  // About 17 cups, many half hidden; the clearly visible ones must be there.
  EXPECT_GE(dets.size(), 8u);
  EXPECT_LE(dets.size(), 17u);
  // Centres of cups checked by hand on scene2/rgb/0000.png (pixels): the standing cup in
  // the middle, the cup on the left, the cup at the front, and two lids seen from above at
  // the back.
  const std::vector<cv::Point2f> cups{{345, 242}, {194, 303}, {349, 341}, {332, 170}, {257, 162}};
  for (const auto& c : cups) {
    bool found = false;
    for (const auto& d : dets) found = found || std::hypot(d.x - c.x, d.y - c.y) < 20.f;
    EXPECT_TRUE(found) << "no detection on the cup at " << c;
  }
  // The pile lies within this box; the table, the markers and the cable are outside it.
  const cv::Rect2f pile(160, 110, 320, 300);
  for (const auto& d : dets) {
    EXPECT_TRUE(pile.contains({d.x, d.y})) << d.object << " detected off the pile at " << d.x << "," << d.y;
    EXPECT_EQ(d.object, "coffee_cup");
    EXPECT_GE(d.templates, 3);
  }
  // No duplicates: no two detections on one cup.
  for (std::size_t i = 0; i < dets.size(); ++i)
    for (std::size_t j = i + 1; j < dets.size(); ++j)
      EXPECT_GT(std::hypot(dets[i].x - dets[j].x, dets[i].y - dets[j].y), 30.f) << i << " and " << j;
  // Best first.
  for (std::size_t i = 1; i < dets.size(); ++i) EXPECT_GE(dets[i - 1].score, dets[i].score);
}

TEST(DetectIcbin, VerifiedPosesSitOnTheCupsTheHypothesesFound) {
  VKPOSE_REQUIRE_SHARED_DATA();
  const auto& hyps = icbinScene2().result.detections;  // on distinct cups (the test above)
  const DetectionResult& r = icbinScene2Poses().result;
  // Measured with the CLI's bank: 10 accepted (8 before the silhouette counted over what the
  // scene does not hide; 6 without stage 5's runners-up); cups pressed against cups at the same
  // depth show too little of a depth step around their outline and are rejected (VerifyParams).
  EXPECT_GE(r.detections.size(), 4u);
  // Since the silhouette test counts over the outline nothing hides (2026-12-01), 10: one more
  // is a cup lying at the right of the pile, lid to the lower left, found from a runner-up
  // that the stages-1-5 run drops (checked by hand on the overlay).
  std::vector<cv::Point2f> cups{{442, 239}};
  for (const auto& h : hyps) cups.emplace_back(h.x, h.y);
  for (const Detection& d : r.detections) {
    EXPECT_TRUE(d.verified);
    bool on_cup = false;
    for (const auto& c : cups) on_cup = on_cup || std::hypot(d.x - c.x, d.y - c.y) < 20.f;
    EXPECT_TRUE(on_cup) << "a pose at " << d.x << "," << d.y << " is on none of the cups";
    // phi over the points nothing hides passes 0.4 (verify.occlusion_credit): over all of them
    // at least 0.4 x (1 - credit).
    EXPECT_GT(d.collision_rate, 0.4f * (1.f - DetectorParams{}.verify.occlusion_credit));
    // Mean squared pair distance under (5.5 mm)^2 where the score says the pose is sure (0.5,
    // docs/evaluation.md). Below it a pose may fit more loosely: since stage 5's runners-up
    // (2026-11-28), a cup leaning at the back, half hidden, is found at score 0.22 with 38.7 mm^2
    // (see-through 0.13, depth fit 0.74); the others fit within 6-15 mm^2.
    if (d.score >= 0.5f) {
      EXPECT_LT(d.icp_fitness, 30e-6);
    }
    // The outline of the posed model covers the detection's centre.
    const auto outline = silhouette(icbinCupBank().mesh, d.pose, loadCamera(test::sharedData() + "/icbin/camera.json"));
    ASSERT_FALSE(outline.empty());
    EXPECT_GE(cv::pointPolygonTest(outline.front(), cv::Point2f(d.x, d.y), false), 0.0);
  }
  for (std::size_t i = 0; i < r.detections.size(); ++i)
    for (std::size_t j = i + 1; j < r.detections.size(); ++j)
      EXPECT_GT((r.detections[i].pose.t - r.detections[j].pose.t).norm(), 0.03f) << i << " and " << j;
  // Every hypothesis that went through stages 6-8 is accounted for, with a reason if rejected.
  for (const Detection& d : r.rejected) EXPECT_FALSE(d.rejection.empty());
  const auto doc = nlohmann::json::parse(icbinScene2Poses().json);
  for (const auto& d : doc.at("detections")) {
    for (const char* key : {"R", "t", "collision_rate", "icp_fitness", "gamma", "silhouette_support"})
      EXPECT_TRUE(d.contains(key)) << key;
  }
  for (const char* stage : {"initial_pose", "mls", "icp", "verification"})
    EXPECT_TRUE(doc.at("timings_ms").contains(stage)) << stage;
}

TEST(DetectIcbin, WritesTheDetectionJsonScriptsRelyOn) {
  VKPOSE_REQUIRE_SHARED_DATA();
  const auto doc = nlohmann::json::parse(icbinScene2().json);
  EXPECT_EQ(doc.at("rgb"), "rgb.png");
  EXPECT_EQ(doc.at("depth"), "depth.png");
  EXPECT_FALSE(doc.at("device").get<std::string>().empty());
  const auto& dets = doc.at("detections");
  ASSERT_EQ(dets.size(), icbinScene2().result.detections.size());
  for (const auto& d : dets) {
    EXPECT_EQ(d.at("object"), "coffee_cup");
    EXPECT_GT(d.at("score").get<double>(), 0.0);
    EXPECT_LE(d.at("score").get<double>(), 1.0);
    ASSERT_EQ(d.at("bbox").size(), 4u);
    EXPECT_GT(d.at("bbox")[2].get<double>(), 20.0);
    ASSERT_EQ(d.at("R").size(), 9u);
    ASSERT_EQ(d.at("t").size(), 3u);
    // A rotation, row-major; t in metres in front of the camera at the pile's distance.
    Eigen::Matrix3d R;
    for (int k = 0; k < 9; ++k) R(k / 3, k % 3) = d.at("R")[static_cast<std::size_t>(k)].get<double>();
    EXPECT_NEAR((R.transpose() * R - Eigen::Matrix3d::Identity()).norm(), 0.0, 1e-4);
    EXPECT_NEAR(R.determinant(), 1.0, 1e-4);
    const double z = d.at("t")[2].get<double>();
    EXPECT_GT(z, 0.5);
    EXPECT_LT(z, 1.0);
    EXPECT_GE(d.at("templates").get<int>(), 3);
  }
  // Per-stage timings.
  const auto& t = doc.at("timings_ms");
  for (const char* stage : {"features", "similarity", "clustering", "scoring", "nms", "total"}) {
    ASSERT_TRUE(t.contains(stage)) << stage;
    EXPECT_GE(t.at(stage).get<double>(), 0.0);
  }
}

TEST(DetectIcbin, PoseStagesOnOneThreadFindTheSameAsOnMany) {
  // Stages 6-8 run their candidates on DetectorParams::threads threads; the detections, the
  // rejected candidates and their order must not depend on how many (timings aside).
  VKPOSE_REQUIRE_SHARED_DATA();
  const IcbinResult one = detectIcbinScene2(true, 1);
  const IcbinResult& many = icbinScene2Poses();  // every core (at least 2 on any CI machine)
  const IcbinResult four = detectIcbinScene2(true, 4);
  auto withoutTimings = [](const std::string& json) {
    auto doc = nlohmann::json::parse(json);
    doc.erase("timings_ms");
    return doc;
  };
  EXPECT_EQ(one.result.pose_threads, 1u);
  EXPECT_EQ(four.result.pose_threads, 4u);
  ASSERT_GT(one.result.refined_candidates, 4u);
  ASSERT_FALSE(one.result.detections.empty());
  EXPECT_EQ(one.result.refined_candidates, many.result.refined_candidates);
  EXPECT_EQ(withoutTimings(one.json), withoutTimings(many.json));
  EXPECT_EQ(withoutTimings(one.json), withoutTimings(four.json));
  EXPECT_GT(one.result.pose_wall_ms, 0.0);
  EXPECT_GT(one.result.pose_cpu_ms, 0.0);
}

TEST(DetectIcbin, TheFirstFitRefinesFewerStartsAndFindsTheSameCups) {
  // The first fit stops the starts that cannot pass stage 8 before MLS and ICP (about half
  // of the starts go on here); the cups found must be the same ones, in the same places.
  VKPOSE_REQUIRE_SHARED_DATA();
  const IcbinResult& screened = icbinScene2Poses();
  const IcbinResult all = detectIcbinScene2(true, 0, false);
  const auto& found = screened.result.detections;
  ASSERT_GE(found.size(), 5u);
  ASSERT_EQ(found.size(), all.result.detections.size());
  for (const Detection& d : all.result.detections) {
    const bool kept = std::any_of(found.begin(), found.end(),
                                  [&](const Detection& s) { return (s.pose.t - d.pose.t).norm() < 0.005f; });
    EXPECT_TRUE(kept) << "the cup at " << d.pose.t.transpose() << " was lost";
  }
  EXPECT_LT(screened.result.refined_candidates * 3, all.result.refined_candidates * 2);
  EXPECT_LE(static_cast<double>(screened.result.refined_candidates), 2.5 * static_cast<double>(found.size()));
  // The stopped starts are reported, with the first fit's measurements and why.
  const auto stopped = std::count_if(screened.result.rejected.begin(), screened.result.rejected.end(),
                                     [](const Detection& r) { return r.rejection.find("first fit") != std::string::npos; });
  EXPECT_EQ(static_cast<std::size_t>(stopped) + screened.result.refined_candidates, all.result.refined_candidates);
}

TEST(DetectIcbin, FramesInFlightFindWhatFrameByFrameFinds) {
  // detectSequence starts each next frame's stages 1-2 on the GPU while the CPU stages of the
  // current one run; the detections must not change.
  VKPOSE_REQUIRE_SHARED_DATA();
  const std::string d = test::sharedData() + "/icbin/";
  const Camera camera = loadCamera(d + "camera.json");
  std::vector<LinemodFrame> frames;
  for (const char* scene : {"scene2/", "scene3/"})
    for (const char* image : {"0000.png", "0001.png"})
      frames.push_back(loadFrame(d + scene + "rgb/" + image, d + scene + "depth/" + image, camera.depth_scale));
  Detector detector(test::context(), {icbinCupBank()}, DetectorParams{});
  std::vector<DetectionResult> one_by_one;
  for (const auto& f : frames) one_by_one.push_back(detector.detect(f, camera));
  const auto in_flight = detector.detectSequence(frames, std::vector<Camera>(frames.size(), camera));
  ASSERT_EQ(in_flight.size(), frames.size());
  int found = 0;
  for (std::size_t i = 0; i < frames.size(); ++i) {
    EXPECT_EQ(in_flight[i].matches, one_by_one[i].matches) << "frame " << i;
    ASSERT_EQ(in_flight[i].detections.size(), one_by_one[i].detections.size()) << "frame " << i;
    for (std::size_t k = 0; k < in_flight[i].detections.size(); ++k) {
      const Detection &a = in_flight[i].detections[k], &b = one_by_one[i].detections[k];
      EXPECT_EQ(a.template_index, b.template_index);
      EXPECT_FLOAT_EQ(a.score, b.score);
      EXPECT_LT((a.pose.t - b.pose.t).norm(), 1e-3) << "frame " << i << " detection " << k;
      ++found;
    }
  }
  EXPECT_GT(found, 0) << "no detections to compare";
  // A frame the sequence cannot use is reported on its turn, and the detector goes on.
  std::vector<LinemodFrame> with_bad = {frames[0], frames[1]};
  with_bad[1].depth_mm = cv::Mat::zeros(with_bad[1].depth_mm.size(), CV_16UC1);
  EXPECT_THROW(detector.detectSequence(with_bad, {camera, camera}), InputError);
  EXPECT_EQ(detector.detect(frames[0], camera).detections.size(), one_by_one[0].detections.size());
}

TEST(DetectionIo, RefusesToOverwriteWithoutForce) {
  const auto dir = std::filesystem::temp_directory_path() / "vkpose_detect_io_test";
  std::filesystem::create_directories(dir);
  const std::string path = (dir / "det.json").string();
  std::filesystem::remove(path);
  writeTextFile(path, "{}\n", false);
  EXPECT_THROW(writeTextFile(path, "{\"x\": 1}\n", false), InputError);
  writeTextFile(path, "{\"x\": 1}\n", true);
  const cv::Mat image(8, 8, CV_8UC3, cv::Scalar(1, 2, 3));
  const std::string png = (dir / "overlay.png").string();
  std::filesystem::remove(png);
  writeImage(png, drawDetections(image, {}, {}, Camera{}), false);
  EXPECT_THROW(writeImage(png, image, false), InputError);
  EXPECT_THROW(writeImage((dir / "missing" / "x.png").string(), image, true), InputError);
  std::filesystem::remove_all(dir);
}

TEST(DetectionIo, SideBySideOverlayShowsTheDepthWithTheSameDrawing) {
  const cv::Mat bgr(240, 320, CV_8UC3, cv::Scalar(90, 90, 90));
  cv::Mat depth(240, 320, CV_16UC1);
  for (int y = 0; y < depth.rows; ++y)
    for (int x = 0; x < depth.cols; ++x) depth.at<uint16_t>(y, x) = static_cast<uint16_t>(500 + 2 * x);
  depth(cv::Rect(290, 0, 30, 30)).setTo(0);  // no depth: black
  DetectionResult result;
  Detection d;
  d.object = "box";
  d.bbox = cv::Rect2f(150, 100, 60, 60);
  d.x = 180, d.y = 130;
  result.detections.push_back(d);
  OverlayOptions options;
  options.depth_mm = depth;
  const cv::Mat both = drawDetections(bgr, result, {}, Camera{}, options);
  ASSERT_EQ(both.size(), cv::Size(640, 240));
  EXPECT_EQ(both.at<cv::Vec3b>(10, 320 + 305), cv::Vec3b(0, 0, 0)) << "no depth is black";
  // Near is red, far is blue (BGR).
  const cv::Vec3b near = both.at<cv::Vec3b>(200, 320 + 2), far = both.at<cv::Vec3b>(200, 320 + 317);
  EXPECT_GT(near[2], near[0]);
  EXPECT_GT(far[0], far[2]);
  // The colour half is the plain overlay; the box is drawn on both halves at the same place.
  const cv::Mat plain = drawDetections(bgr, result, {}, Camera{});
  EXPECT_EQ(cv::norm(both(cv::Rect(0, 0, 320, 240)), plain, cv::NORM_INF), 0.0);
  const cv::Vec3b box_colour = plain.at<cv::Vec3b>(130, 150);
  EXPECT_NE(box_colour, cv::Vec3b(67, 67, 67)) << "the box edge is drawn on the colour half";
  EXPECT_EQ(both.at<cv::Vec3b>(130, 320 + 150), box_colour) << "and on the depth half";
  options.depth_mm = cv::Mat(10, 10, CV_16UC1, cv::Scalar(1000));
  EXPECT_THROW(drawDetections(bgr, result, {}, Camera{}, options), InputError);
}

}  // namespace
}  // namespace vkpose
