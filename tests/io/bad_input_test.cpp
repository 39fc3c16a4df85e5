// Bad input: a clear InputError (naming the file and the problem) or an empty result, never
// a crash. One test per case: missing, empty and truncated files of every kind, wrong bit
// depths, odd image sizes, extreme depths and intrinsics, degenerate and out-of-scale meshes,
// banks of other versions, and more templates than fit in GPU memory.
#include <array>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <memory>
#include <functional>
#include <sstream>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "gpu/vulkan.hpp"
#include "hypotheses/cluster_score.hpp"
#include "match/features.hpp"
#include "match/matcher.hpp"
#include "mesh_support.hpp"
#include "test_support.hpp"
#include "vkpose/bank.hpp"
#include "vkpose/detector.hpp"
#include "vkpose/device.hpp"
#include "vkpose/error.hpp"
#include "vkpose/evaluation.hpp"
#include "vkpose/frame.hpp"
#include "vkpose/geometry.hpp"

namespace vkpose {
namespace {

LinemodFrame frameOf(cv::Size colour, cv::Size depth, uint16_t depth_value = 800) {
  LinemodFrame f;
  f.bgr = cv::Mat(colour, CV_8UC3, cv::Scalar(30, 60, 90));
  if (colour.area() > 0) cv::circle(f.bgr, {colour.width / 2, colour.height / 2}, colour.width / 4 + 1, {200, 10, 10}, -1);
  f.depth_mm = cv::Mat(depth, CV_16UC1, cv::Scalar(depth_value));
  return f;
}

std::vector<LinemodTemplate> someTemplates() {
  LinemodTemplate t;
  t.levels.resize(2);
  for (int l = 0; l < 2; ++l) {
    t.levels[l].width = 40 >> l;
    t.levels[l].height = 40 >> l;
    for (int i = 0; i < 20; ++i)
      t.levels[l].features.push_back({(i * 7) % (40 >> l), (i * 3) % (40 >> l), static_cast<uint8_t>(i % 8),
                                      i % 2 ? Modality::DepthNormal : Modality::ColourGradient});
  }
  return {t};
}

/// A folder of this test process (ctest runs tests in parallel processes).
std::string scratch() { return test::scratchDir("vkpose_bad_input_"); }

std::string writeFile(const std::string& name, const std::string& bytes) {
  const std::string path = scratch() + "/" + name;
  std::ofstream(path, std::ios::binary | std::ios::trunc) << bytes;
  return path;
}

std::string readFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

using test::expectInputError;

/// A bank of one template on a 5 cm cube, made in code (no training): small and CPU-only.
TemplateBank tinyBank() {
  TemplateBank b;
  b.mesh = test::boxMesh({0.05f, 0.05f, 0.05f});
  b.mesh.name = b.object = "cube";
  b.diameter = b.mesh.diameter;
  BankTemplate t;
  t.linemod = someTemplates()[0];
  t.pose.R = Eigen::Matrix3f::Identity();
  t.pose.t = {0.f, 0.f, 0.7f};
  t.distance = 0.7f;
  t.anchor_x = t.anchor_y = 20.f;
  t.crop.stride = 2;
  t.crop.cols = t.crop.rows = 4;
  t.crop.depth_01mm.assign(16, 6750);
  for (int i = 0; i < 16; ++i) t.crop.normals.insert(t.crop.normals.end(), {0, 0, -127});
  b.templates = {t};
  return b;
}

std::string tinyBankBytes() {
  const std::string path = scratch() + "/tiny.vkpb";
  saveBank(tinyBank(), path);
  return readFile(path);
}

class BadInput : public ::testing::Test {
 protected:
  LinemodMatcher matcher{test::context()};
  void SetUp() override { matcher.setTemplates(someTemplates()); }
};

TEST_F(BadInput, ColourAndDepthOfDifferentSizes) {
  EXPECT_THROW(matcher.match(frameOf({640, 480}, {320, 240})), InputError);
}

TEST_F(BadInput, EmptyImages) { EXPECT_THROW(matcher.match(frameOf({0, 0}, {0, 0})), InputError); }

TEST_F(BadInput, OnePixelImage) { EXPECT_THROW(matcher.match(frameOf({1, 1}, {1, 1})), InputError); }

TEST_F(BadInput, TinyOddImagesGiveAResultNotACrash) {
  EXPECT_NO_THROW(matcher.match(frameOf({2, 2}, {2, 2})));
  EXPECT_NO_THROW(matcher.match(frameOf({17, 13}, {17, 13})));
}

TEST_F(BadInput, DepthAllZeroGivesNoDepthLabels) {
  const auto f = frameOf({64, 48}, {64, 48}, 0);
  const auto pyramid = quantizeFramePyramid(f, {});
  EXPECT_EQ(cv::countNonZero(pyramid[0].labels[1]), 0);
  EXPECT_NO_THROW(matcher.match(f));
}

TEST_F(BadInput, WrongImageTypes) {
  auto f = frameOf({64, 48}, {64, 48});
  f.depth_mm.convertTo(f.depth_mm, CV_32F);
  EXPECT_THROW(matcher.match(f), InputError);
}

TEST(BadInputFiles, MissingAndCorruptFilesNameTheFile) {
  const auto dir = std::filesystem::path(scratch());
  const std::string missing = (dir / "missing.png").string();
  try {
    loadFrame(missing, missing);
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("missing.png"), std::string::npos);
  }
  const std::string corrupt = (dir / "corrupt.png").string();
  std::ofstream(corrupt) << "not a png";
  EXPECT_THROW(loadFrame(corrupt, corrupt), InputError);
  // An 8-bit PNG where 16-bit depth is expected.
  const std::string rgb8 = (dir / "rgb8.png").string();
  cv::imwrite(rgb8, cv::Mat(8, 8, CV_8UC3, cv::Scalar(1, 2, 3)));
  EXPECT_THROW(loadFrame(rgb8, rgb8), InputError);
  EXPECT_THROW(loadFrame(rgb8, rgb8, -1.0), InputError);
}

TEST(BadInputTemplates, AreRejectedWithAMessage) {
  FeatureParams p;
  auto t = someTemplates();
  t[0].levels.pop_back();
  EXPECT_THROW(validateTemplates(t, p), InputError);
  t = someTemplates();
  t[0].levels[0].features[0].bin = 9;
  EXPECT_THROW(validateTemplates(t, p), InputError);
  t = someTemplates();
  t[0].levels[1].features.clear();
  EXPECT_THROW(validateTemplates(t, p), InputError);
  FeatureParams bad;
  bad.T = {5, 8, 12};
  EXPECT_THROW(validateFeatureParams(bad), InputError);
  EXPECT_THROW(LinemodMatcher(test::context(), {}, MatchParams{0.0f}), InputError);
  MatchParams outside;
  outside.outside_response = 5;
  test::expectInputError([&] { LinemodMatcher(test::context(), {}, outside); }, {"outside the image", "0..4", "5"});
  test::expectInputError([&] { matchTemplatesReference({}, someTemplates(), p, outside); },
                         {"outside the image", "0..4", "5"});
}

// ---- files: missing, empty, truncated ---------------------------------------------------

TEST(BadInputBank, Missing) {
  expectInputError([] { loadBank(scratch() + "/absent.vkpb"); }, {"absent.vkpb", "no such template bank"});
}

TEST(BadInputBank, Empty) {
  const auto path = writeFile("empty.vkpb", "");
  expectInputError([&] { loadBank(path); }, {"empty.vkpb", "empty file"});
}

TEST(BadInputBank, Truncated) {
  const std::string bytes = tinyBankBytes();
  ASSERT_EQ(loadBank(writeFile("whole.vkpb", bytes)).templates.size(), 1u);
  for (const std::size_t n : {std::size_t{5}, std::size_t{30}, bytes.size() / 2, bytes.size() - 1}) {
    const auto path = writeFile("cut.vkpb", bytes.substr(0, n));
    expectInputError([&] { loadBank(path); }, {"cut.vkpb", "truncated"});
  }
}

TEST(BadInputBank, Version1And99AreRefused) {
  std::string bytes = tinyBankBytes();
  for (const uint8_t v : {1, 99}) {
    bytes[8] = static_cast<char>(v);
    const auto path = writeFile("old.vkpb", bytes);
    expectInputError([&] { loadBank(path); }, {"old.vkpb", "version " + std::to_string(v), "train it again"});
  }
}

TEST(BadInputBank, CropsLargerThanTrainingMakesAreRefused) {
  // The cluster score's kernel loops over a crop's cells; training makes at most 25 x 25.
  TemplateBank bank = tinyBank();
  BankTemplate& t = bank.templates[0];
  const std::string path = scratch() + "/big_crop.vkpb";
  for (const int cells : {kCropCells + 1, kCropCells + 2}) {
    t.crop.cols = t.crop.rows = cells;
    t.crop.depth_01mm.assign(static_cast<std::size_t>(cells * cells), 6750);
    t.crop.normals.assign(static_cast<std::size_t>(cells * cells * 3), 0);
    saveBank(bank, path);
    if (cells == kCropCells + 1)
      EXPECT_EQ(loadBank(path).templates.at(0).crop.cols, cells);
    else
      expectInputError([&] { loadBank(path); }, {"big_crop.vkpb", "crop 26x26", "at most 25x25"});
  }
}

TEST(BadInputBank, WrongMagic) {
  std::string bytes = tinyBankBytes();
  bytes[0] = 'X';
  const auto path = writeFile("magic.vkpb", bytes);
  expectInputError([&] { loadBank(path); }, {"magic.vkpb", "not a vkpose template bank"});
}

TEST(BadInputCamera, MissingEmptyTruncated) {
  expectInputError([] { loadCamera(scratch() + "/absent.json"); }, {"absent.json", "cannot open"});
  const auto empty = writeFile("empty_camera.json", "");
  expectInputError([&] { loadCamera(empty); }, {"empty_camera.json", "not valid JSON"});
  const auto cut = writeFile("cut_camera.json", R"({"cam_K": [572.4, 0.0, 325.2, 0.0, 57)");
  expectInputError([&] { loadCamera(cut); }, {"cut_camera.json", "not valid JSON"});
}

TEST(BadInputCamera, ZeroAndNonFiniteIntrinsics) {
  const auto zero = writeFile("zero.json", R"({"fx": 0, "fy": 0, "cx": 320, "cy": 240})");
  expectInputError([&] { loadCamera(zero); }, {"zero.json", "focal lengths must be positive"});
  // JSON has no NaN; a number past the double range reads as infinity.
  const auto inf = writeFile("inf.json", R"({"fx": 1e999, "fy": 500, "cx": 320, "cy": 240})");
  expectInputError([&] { loadCamera(inf); }, {"inf.json"});
  Camera nan;
  nan.fx = std::numeric_limits<double>::quiet_NaN();
  expectInputError([&] { validateCamera(nan, "my camera"); }, {"my camera", "focal lengths"});
  nan = Camera{};
  nan.cy = std::numeric_limits<double>::quiet_NaN();
  expectInputError([&] { validateCamera(nan, "my camera"); }, {"principal point"});
}

TEST(BadInputCamera, ImageSizePastTheIntRangeIsAnErrorNotUndefinedBehaviour) {
  // Regression (UBSan, float-cast-overflow): width 1e300 was cast to int before the check.
  const auto big = writeFile("big.json", R"({"fx": 500, "fy": 500, "cx": 320, "cy": 240, "width": 1e300})");
  expectInputError([&] { loadCamera(big); }, {"big.json", "width"});
  const auto neg = writeFile("neg.json", R"({"fx": 500, "fy": 500, "cx": 320, "cy": 240, "height": -3e12})");
  expectInputError([&] { loadCamera(neg); }, {"neg.json", "height"});
}

TEST(BadInputBopJson, BoxPastTheIntRangeIsAnErrorNotUndefinedBehaviour) {
  // Regression (UBSan, float-cast-overflow): bbox values were cast to int unchecked.
  const auto path = writeFile("big_gt_info.json", R"({"3": [{"bbox_obj": [1e300, 2, 3, 4], "bbox_visib": [1, 2, 3, 4],)"
                                                  R"( "px_count_all": 9, "px_count_valid": 9, "px_count_visib": 9,)"
                                                  R"( "visib_fract": 1.0}]})");
  expectInputError([&] { loadSceneGtInfo(path); }, {"big_gt_info.json", "bbox_obj", "not a pixel coordinate"});
}

/// The BOP per-image and per-object JSON readers, by name.
const std::vector<std::pair<std::string, std::function<void(const std::string&)>>>& bopReaders() {
  static const std::vector<std::pair<std::string, std::function<void(const std::string&)>>> readers = {
      {"scene_gt.json", [](const std::string& p) { loadSceneGt(p); }},
      {"scene_gt_info.json", [](const std::string& p) { loadSceneGtInfo(p); }},
      {"scene_camera.json", [](const std::string& p) { loadSceneCamera(p); }},
      {"models_info.json", [](const std::string& p) { loadModelsInfo(p); }}};
  return readers;
}

TEST(BadInputBopJson, Missing) {
  for (const auto& [name, read] : bopReaders()) {
    const std::string path = scratch() + "/absent_" + name;
    expectInputError([&] { read(path); }, {path, "cannot open"});
  }
}

TEST(BadInputBopJson, Empty) {
  for (const auto& [name, read] : bopReaders()) {
    const auto path = writeFile(name, "");
    expectInputError([&] { read(path); }, {path, "not valid JSON"});
  }
}

TEST(BadInputBopJson, Truncated) {
  const std::map<std::string, std::string> whole = {
      {"scene_gt.json", R"({"3": [{"cam_R_m2c": [1, 0, 0, 0, 1, 0, 0, 0, 1], "cam_t_m2c": [0, 0, 800], "obj_id": 1}]})"},
      {"scene_gt_info.json", R"({"3": [{"bbox_obj": [1, 2, 3, 4], "bbox_visib": [1, 2, 3, 4], "px_count_all": 9,)"
                             R"( "px_count_valid": 9, "px_count_visib": 9, "visib_fract": 1.0}]})"},
      {"scene_camera.json", R"({"3": {"cam_K": [572.4, 0, 325.3, 0, 573.6, 242.0, 0, 0, 1], "depth_scale": 1.0}})"},
      {"models_info.json", R"({"1": {"diameter": 102.1, "min_x": -37.9, "size_x": 75.9}})"}};
  for (const auto& [name, read] : bopReaders()) {
    const std::string& text = whole.at(name);
    EXPECT_NO_THROW(read(writeFile(name, text))) << name;
    for (const std::size_t n : {std::size_t{1}, text.size() / 2, text.size() - 1}) {
      const auto path = writeFile("cut_" + name, text.substr(0, n));
      expectInputError([&] { read(path); }, {path, "not valid JSON"});
    }
  }
}

TEST(BadInputPoses, MissingEmptyTruncated) {
  expectInputError([] { loadTejaniPoses(scratch() + "/absent.txt"); }, {"absent.txt", "cannot open"});
  const auto empty = writeFile("empty_poses.txt", "");
  expectInputError([&] { loadTejaniPoses(empty); }, {"empty_poses.txt", "empty file"});
  const auto cut = writeFile("cut_poses.txt", "1\n1 0 0 0.1\n0 1 0 0.2\n0 0 1");
  expectInputError([&] { loadTejaniPoses(cut); }, {"cut_poses.txt", "1 poses", "ends at line 4"});
}

TEST(BadInputResults, MissingEmptyTruncated) {
  expectInputError([] { loadBopResults(scratch() + "/absent.csv"); }, {"absent.csv", "cannot open"});
  EXPECT_TRUE(loadBopResults(writeFile("empty.csv", "")).empty());
  const auto cut = writeFile("cut.csv", "scene_id,im_id,obj_id,score,R,t,time\n2,3,1,0.9,1 0 0 0 1 0 0 0 1,10 2");
  expectInputError([&] { loadBopResults(cut); }, {"cut.csv", "line 2"});
}

// ---- meshes ------------------------------------------------------------------------------

/// A binary STL of the given triangles.
std::string binaryStl(const std::vector<std::array<Eigen::Vector3f, 3>>& triangles) {
  std::string b(80, ' ');
  const auto put = [&](const auto& v) { b.append(reinterpret_cast<const char*>(&v), sizeof(v)); };
  put(static_cast<uint32_t>(triangles.size()));
  for (const auto& t : triangles) {
    for (int k = 0; k < 3; ++k) put(0.f);
    for (const auto& v : t)
      for (int k = 0; k < 3; ++k) put(v[k]);
    put(uint16_t{0});
  }
  return b;
}

/// A tetrahedron with edges of `size`.
std::vector<std::array<Eigen::Vector3f, 3>> tetrahedron(float size) {
  const Eigen::Vector3f a(0, 0, 0), b(size, 0, 0), c(0, size, 0), d(0, 0, size);
  return {{a, c, b}, {a, b, d}, {a, d, c}, {b, c, d}};
}

TEST(BadInputMesh, MissingEmptyTruncated) {
  expectInputError([] { loadMesh(scratch() + "/absent.stl"); }, {"absent.stl", "no such mesh file"});
  const auto empty = writeFile("empty.stl", "");
  expectInputError([&] { loadMesh(empty); }, {"empty.stl", "empty"});
  const std::string stl = binaryStl(tetrahedron(0.05f));
  EXPECT_EQ(loadMesh(writeFile("tetra.stl", stl)).faces.size(), 4u);
  const auto cut = writeFile("cut.stl", stl.substr(0, stl.size() - 70));
  expectInputError([&] { loadMesh(cut); }, {"cut.stl"});
}

TEST(BadInputMesh, NoFaces) {
  const auto path = writeFile("points.obj", "v 0 0 0\nv 0.1 0 0\nv 0 0.1 0\n");
  expectInputError([&] { loadMesh(path, MeshUnits::Metres); }, {"points.obj"});
  Mesh m;
  m.name = "built";
  m.vertices = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  expectInputError([&] { finishMesh(m); }, {"built", "no triangles"});
}

TEST(BadInputMesh, DegenerateTriangles) {
  // Only degenerate triangles (all corners at one point): no extent.
  const Eigen::Vector3f p(0.01f, 0.02f, 0.03f);
  const auto point = writeFile("point.stl", binaryStl({{p, p, p}, {p, p, p}}));
  expectInputError([&] { loadMesh(point, MeshUnits::Metres); }, {"point.stl"});
  // Collinear corners (zero area) next to a real tetrahedron: loads, and the tetrahedron is there.
  auto tris = tetrahedron(0.05f);
  tris.push_back({Eigen::Vector3f(0, 0, 0), Eigen::Vector3f(0.01f, 0, 0), Eigen::Vector3f(0.02f, 0, 0)});
  const Mesh m = loadMesh(writeFile("sliver.stl", binaryStl(tris)), MeshUnits::Metres);
  EXPECT_GE(m.faces.size(), 4u);
  EXPECT_NEAR(m.diameter, 0.05f * std::sqrt(2.f), 1e-6f);
  for (const auto& n : m.normals) EXPECT_TRUE(n.allFinite());
}

TEST(BadInputMesh, HugeScale) {
  const auto path = writeFile("huge.stl", binaryStl(tetrahedron(1e6f)));
  expectInputError([&] { loadMesh(path, MeshUnits::Metres); }, {"huge.stl", "1 mm to 10 m", "--units"});
  expectInputError([&] { loadMesh(path, MeshUnits::Auto); }, {"huge.stl", "1 mm to 10 m"});
}

TEST(BadInputMesh, TinyScale) {
  const auto path = writeFile("tiny.stl", binaryStl(tetrahedron(1e-6f)));
  expectInputError([&] { loadMesh(path, MeshUnits::Metres); }, {"tiny.stl", "1 mm to 10 m"});
  expectInputError([&] { loadMesh(path, MeshUnits::Millimetres); }, {"tiny.stl", "1 mm to 10 m"});
}

// ---- images ------------------------------------------------------------------------------

std::string colourPng(const std::string& name, cv::Size size) {
  const std::string path = scratch() + "/" + name;
  cv::imwrite(path, cv::Mat(size, CV_8UC3, cv::Scalar(10, 20, 30)));
  return path;
}

std::string depthPng(const std::string& name, cv::Size size, uint16_t value = 800) {
  const std::string path = scratch() + "/" + name;
  cv::imwrite(path, cv::Mat(size, CV_16UC1, cv::Scalar(value)));
  return path;
}

TEST(BadInputPng, Missing) {
  const auto rgb = colourPng("rgb.png", {64, 48});
  const auto depth = depthPng("depth.png", {64, 48});
  EXPECT_NO_THROW(loadFrame(rgb, depth));
  expectInputError([&] { loadFrame(scratch() + "/absent_rgb.png", depth); }, {"absent_rgb.png", "does not exist"});
  expectInputError([&] { loadFrame(rgb, scratch() + "/absent_depth.png"); }, {"absent_depth.png", "does not exist"});
}

TEST(BadInputPng, Empty) {
  const auto empty = writeFile("empty.png", "");
  const auto depth = depthPng("depth.png", {64, 48});
  expectInputError([&] { loadFrame(empty, depth); }, {"empty.png", "colour"});
  expectInputError([&] { loadFrame(colourPng("rgb.png", {64, 48}), empty); }, {"empty.png", "depth"});
}

TEST(BadInputPng, Truncated) {
  const auto rgb = colourPng("rgb.png", {64, 48});
  const auto depth = depthPng("depth.png", {64, 48});
  const std::string rgb_bytes = readFile(rgb), depth_bytes = readFile(depth);
  for (const std::size_t n : {std::size_t{8}, std::size_t{40}, rgb_bytes.size() / 2}) {
    const auto cut = writeFile("cut_rgb.png", rgb_bytes.substr(0, n));
    expectInputError([&] { loadFrame(cut, depth); }, {"cut_rgb.png"});
  }
  const auto cut = writeFile("cut_depth.png", depth_bytes.substr(0, depth_bytes.size() / 2));
  expectInputError([&] { loadFrame(rgb, cut); }, {"cut_depth.png"});
}

TEST(BadInputPng, EightBitDepth) {
  const std::string path = scratch() + "/depth8.png";
  cv::imwrite(path, cv::Mat(48, 64, CV_8UC1, cv::Scalar(80)));
  expectInputError([&] { loadFrame(colourPng("rgb.png", {64, 48}), path); }, {"depth8.png", "16-bit"});
}

TEST(BadInputPng, SixteenBitColour) {
  const std::string path = scratch() + "/rgb16.png";
  cv::imwrite(path, cv::Mat(48, 64, CV_16UC3, cv::Scalar(1000, 2000, 3000)));
  expectInputError([&] { loadFrame(path, depthPng("depth.png", {64, 48})); }, {"rgb16.png", "8 bits"});
}

TEST(BadInputPng, ColourAndDepthOfDifferentSizes) {
  expectInputError([&] { loadFrame(colourPng("rgb.png", {64, 48}), depthPng("depth.png", {32, 24})); },
                   {"rgb.png", "depth.png", "64x48", "32x24", "differ in size"});
}

// ---- frames the matcher and the detector get ---------------------------------------------

TEST_F(BadInput, HugeImageThroughTheMatcherWithATinyBank) {
  // 4000 x 3000 failed in the GPU layer: first with "too many workgroups" (187,500 in one
  // dimension of a dispatch, lavapipe allows 65,535; the frame kernels now lay them out in
  // rows), then with "a binding exceeds maxStorageBufferRange" (a DeviceError, exit code 3 as
  // if there were no GPU). Now: an InputError up front that names the size that fits.
  const auto devName = test::context().device().name;
  const uint64_t bindable = std::min<uint64_t>(test::context().device().max_storage_buffer_range,
                                               test::context().device().max_texel_buffer_elements);
  if (bindable >= (uint64_t{1} << 31)) GTEST_SKIP() << devName << " binds 2 GiB at once: 4000x3000 fits";
  expectInputError([&] { matcher.match(frameOf({4000, 3000}, {4000, 3000})); },
                   {"4000x3000 frame is too large", "scale the frame down to about"});
}

TEST_F(BadInput, DepthAllAtMaximum) {
  // 65.535 m everywhere: a flat wall far away. Matching runs and says only what it may: the
  // template's 40 features at or above the threshold, within the image, the one template.
  const auto f = frameOf({64, 48}, {64, 48}, 65535);
  const std::vector<Match> matches = matcher.match(f);
  for (const Match& m : matches) {
    EXPECT_EQ(m.template_id, 0);
    EXPECT_GE(m.similarity, MatchParams{}.threshold);
    EXPECT_LE(m.similarity, 100.f);
    EXPECT_GT(m.x, -40);
    EXPECT_LT(m.x, 64);
    EXPECT_GT(m.y, -40);
    EXPECT_LT(m.y, 48);
  }
  EXPECT_EQ(matches, matcher.match(f)) << "the same frame matched twice gave other matches";
}

class BadInputDetector : public ::testing::Test {
 protected:
  Detector detector{test::context(), {tinyBank()}};
  Camera camera() const {
    Camera c;
    c.cx = 32;
    c.cy = 24;
    return c;
  }
};

TEST_F(BadInputDetector, DepthAllZeroIsAClearError) {
  expectInputError([&] { detector.detect(frameOf({64, 48}, {64, 48}, 0), camera()); }, {"depth image is all zero"});
}

TEST_F(BadInputDetector, DepthAllAtMaximumFindsNothing) {
  EXPECT_TRUE(detector.detect(frameOf({64, 48}, {64, 48}, 65535), camera()).detections.empty());
}

TEST_F(BadInputDetector, NanAndZeroIntrinsics) {
  const auto f = frameOf({64, 48}, {64, 48});
  for (double Camera::*field : {&Camera::fx, &Camera::fy}) {
    for (const double v : {std::numeric_limits<double>::quiet_NaN(), 0.0}) {
      Camera c = camera();
      c.*field = v;
      expectInputError([&] { detector.detect(f, c); }, {"focal lengths must be positive"});
    }
  }
  Camera c = camera();
  c.cx = std::numeric_limits<double>::quiet_NaN();
  expectInputError([&] { detector.detect(f, c); }, {"principal point"});
}

TEST(BadInputGpuMemory, MoreTemplatesThanFitAreAClearErrorAndLeakNothing) {
  // A mocked device limit: a context that may use 1 MiB, as if the GPU were that small.
  ::setenv("VKPOSE_GPU_MEMORY_LIMIT_MIB", "1", 1);
  std::unique_ptr<GpuContext> ctx;
  try {
    ctx = std::make_unique<GpuContext>();
  } catch (...) {
    ::unsetenv("VKPOSE_GPU_MEMORY_LIMIT_MIB");
    throw;
  }
  ::unsetenv("VKPOSE_GPU_MEMORY_LIMIT_MIB");
  EXPECT_EQ(ctx->state().memory_limit, 1u << 20);
  {
    const std::vector<LinemodTemplate> many(20000, someTemplates()[0]);
    LinemodMatcher m(*ctx);
    expectInputError(
        [&] {
          m.setTemplates(many);
          m.match(frameOf({640, 480}, {640, 480}));
        },
        {"not enough GPU memory", "template banks"});
  }
  EXPECT_EQ(ctx->state().allocated_bytes.load(), 0u) << "buffers left behind after the error";
  expectInputError(
      [] {
        ::setenv("VKPOSE_GPU_MEMORY_LIMIT_MIB", "lots", 1);
        try {
          GpuContext bad;
        } catch (...) {
          ::unsetenv("VKPOSE_GPU_MEMORY_LIMIT_MIB");
          throw;
        }
        ::unsetenv("VKPOSE_GPU_MEMORY_LIMIT_MIB");
      },
      {"VKPOSE_GPU_MEMORY_LIMIT_MIB"});
}

}  // namespace
}  // namespace vkpose
