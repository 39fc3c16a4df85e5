// Bad input: a clear InputError or an empty result, never a crash.
#include <filesystem>
#include <fstream>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "tests/test_support.hpp"
#include "vkpose/error.hpp"
#include "vkpose/frame_io.hpp"
#include "vkpose/matcher.hpp"

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
  const auto dir = std::filesystem::temp_directory_path() / "vkpose_bad_input";
  std::filesystem::create_directories(dir);
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
}

}  // namespace
}  // namespace vkpose
