// The CPU reference of stage 1 against OpenCV, function by function, on real frames (or their
// synthetic stand-ins) and odd sizes.
#include <opencv2/imgproc.hpp>
#include <opencv2/rgbd/linemod.hpp>

#include "match/features.hpp"
#include "match/match_geometry.hpp"
#include "match/matcher.hpp"
#include "test_support.hpp"
#include "vkpose/bank.hpp"

namespace vkpose {
namespace {

std::vector<cv::Mat> testImages() {
  std::vector<cv::Mat> images;
  cv::Mat noise(13, 17, CV_8UC3);
  cv::randu(noise, 0, 256);
  images.push_back(noise);
  cv::Mat odd(93, 127, CV_8UC3);
  cv::randu(odd, 0, 256);
  cv::GaussianBlur(odd, odd, {5, 5}, 0);
  images.push_back(odd);
  images.push_back(test::lmoFrameOrStandIn().bgr);
  images.push_back(test::icbinFrameOrStandIn().bgr);
  return images;
}

int countDifferent(const cv::Mat& a, const cv::Mat& b) {
  cv::Mat diff;
  cv::compare(a.reshape(1), b.reshape(1), diff, cv::CMP_NE);
  return cv::countNonZero(diff);
}

TEST(FeaturesReference, GaussianBlur7IsBitExactWithOpenCv) {
  for (const auto& img : testImages()) {
    cv::Mat expected;
    cv::GaussianBlur(img, expected, {7, 7}, 0, 0, cv::BORDER_REPLICATE);
    EXPECT_EQ(countDifferent(gaussianBlur7(img), expected), 0) << img.cols << "x" << img.rows;
  }
}

TEST(FeaturesReference, PyrDownIsBitExactWithOpenCv) {
  for (const auto& img : testImages()) {
    cv::Mat expected;
    cv::pyrDown(img, expected, cv::Size(img.cols / 2, img.rows / 2));
    EXPECT_EQ(countDifferent(pyrDownColour(img), expected), 0) << img.cols << "x" << img.rows;
  }
}

TEST(FeaturesReference, SpreadingMatchesTheDefinition) {
  cv::Mat labels = cv::Mat::zeros(9, 11, CV_8UC1);
  labels.at<uint8_t>(4, 5) = 8;
  const cv::Mat s = spreadLabels(labels, 3);
  for (int y = 0; y < 9; ++y)
    for (int x = 0; x < 11; ++x) {
      const bool covered = y >= 2 && y <= 4 && x >= 3 && x <= 5;  // windows starting up-left
      EXPECT_EQ(s.at<uint8_t>(y, x), covered ? 8 : 0) << x << "," << y;
    }
}

// OpenCV quantizes gradient angles with phase(), whose fastAtan2 polynomial is off by up to
// about 0.01 degrees; vkpose decides bins exactly. A pixel may differ only where its
// gradient lies that close to a bin edge (or a neighbour's does, through the 3x3 vote).
TEST(FeaturesReference, ColourQuantizationMatchesOpenCvColorGradient) {
  for (const auto& frame : {test::lmoFrameOrStandIn(), test::icbinFrameOrStandIn()}) {
    auto modality = cv::linemod::Modality::create("ColorGradient");
    auto pyramid = modality->process(frame.bgr, cv::Mat());
    cv::Mat bgr = frame.bgr;
    for (int level = 0; level < 2; ++level) {
      if (level > 0) {
        pyramid->pyrDown();
        bgr = pyrDownColour(bgr);
      }
      cv::Mat theirs;
      pyramid->quantize(theirs);
      const cv::Mat ours = quantizeColourGradients(bgr, 10.0f);
      const int labelled = cv::countNonZero(theirs);
      const int differ = countDifferent(ours, theirs);
      EXPECT_GT(labelled, 1000);
      EXPECT_LE(differ, labelled / 2000 + 2) << "level " << level << ": " << differ << " of " << labelled
                                             << " labelled pixels differ from OpenCV";
    }
  }
}

// OpenCV bins depth normals through a 20-cell lookup table of (nx, ny, nz), so its sector
// edges are jagged; vkpose bins the exact least-squares direction into 45-degree sectors
// (same bits, same sector centres). They agree on the large majority of pixels of real
// sensor frames (LM-O 7.5 %, IC-BIN 9.4 % differ). A synthetic stand-in is no test of that: a
// flat surface has one normal, and where that lies near a jagged sector edge a whole bin floor
// or wall changes sector at once (the bin stand-in: 22 % differ, two thirds of them between
// sectors 16 and 32 or 64 and 32), so this test needs the real frames.
TEST(FeaturesReference, DepthQuantizationAgreesWithOpenCvDepthNormal) {
  VKPOSE_REQUIRE_SHARED_DATA();
  for (const auto& frame : {test::lmoFrame(), test::icbinFrame()}) {
    auto modality = cv::linemod::Modality::create("DepthNormal");
    cv::Mat theirs;
    modality->process(frame.depth_mm, cv::Mat())->quantize(theirs);
    const cv::Mat ours = quantizeDepthNormals(frame.depth_mm, 2000, 50);
    const int labelled = cv::countNonZero(theirs);
    EXPECT_GT(labelled, 10000);
    EXPECT_EQ(cv::countNonZero(ours), labelled) << "the same pixels get a normal";
    const int differ = countDifferent(ours, theirs);
    EXPECT_LT(differ, labelled / 5) << differ << " of " << labelled << " normals fall in another sector";
  }
}

TEST(FeaturesReference, DepthMedianIsOpenCvsMedianBlur) {
  // With a difference threshold of 1 mm every label is a lone pixel pattern the median must
  // treat exactly as OpenCV's medianBlur(5); the labels before the median are not exposed,
  // so compare on a label image whose raw labels are known: a flat scene with steps.
  cv::Mat depth(60, 80, CV_16UC1, cv::Scalar(800));
  depth(cv::Rect(20, 10, 30, 30)).setTo(700);
  depth(cv::Rect(50, 30, 20, 20)).setTo(1200);
  const cv::Mat ours = quantizeDepthNormals(depth, 2000, 50);
  EXPECT_GT(cv::countNonZero(ours), 1000);
  auto modality = cv::linemod::Modality::create("DepthNormal");
  cv::Mat theirs;
  modality->process(depth, cv::Mat())->quantize(theirs);
  EXPECT_EQ(countDifferent(ours, theirs), 0);
}

// The coarse range may only drop positions that cannot pass: at every position of the
// centre-in-image range, a template whose features could still score above the threshold
// (4 each inside the image, the outside response each outside) must lie in the trimmed range,
// and the range must be smaller than the whole image for a template near the size of the
// frame: under OpenCV's rule (0 outside) much smaller, with vkpose's default wider but still
// trimmed.
TEST(CoarseRange, KeepsEveryPositionThatCanPassTheThreshold) {
  const LinearMemoryLayout layout = makeLinearMemoryLayout(160, 120, 8, 20, 0);
  cv::RNG rng(7);
  for (int trial = 0; trial < 40; ++trial) {
    TemplateLevel level;
    level.width = rng.uniform(8, 150);
    level.height = rng.uniform(8, 110);
    const int n = rng.uniform(1, 64);
    for (int i = 0; i < n; ++i)
      level.features.push_back({rng.uniform(0, level.width), rng.uniform(0, level.height), 0, Modality::ColourGradient});
    for (const float percent : {50.f, 80.f, 95.f})
      for (const int outside : {0, 3, 4}) {
        const int threshold = match::rawThreshold(n, percent);
        const auto range = match::coarseRange(level, layout, threshold, outside);
        const int wf = templateCells(level.width, layout.T), hf = templateCells(level.height, layout.T);
        for (int r = -(hf / 2); r < layout.cells_y - hf / 2; ++r)
          for (int c = -(wf / 2); c < layout.cells_x - wf / 2; ++c) {
            int inside = 0;
            for (const auto& f : level.features) {
              const int x = c + f.x / layout.T, y = r + f.y / layout.T;
              inside += x >= 0 && x < layout.cells_x && y >= 0 && y < layout.cells_y;
            }
            const bool kept = c >= range.c_lo && c < range.c_lo + range.columns && r >= range.r_lo &&
                              r < range.r_lo + range.rows;
            if (4 * inside + outside * (n - inside) > threshold) {
              EXPECT_TRUE(kept) << "trial " << trial << " at " << c << "," << r << ", outside response " << outside;
            }
          }
      }
  }
  TemplateLevel wide;
  wide.width = 150;
  wide.height = 110;
  for (int y = 0; y < 110; y += 10)
    for (int x = 0; x < 150; x += 10) wide.features.push_back({x, y, 0, Modality::ColourGradient});
  const int n = static_cast<int>(wide.features.size());
  const auto range = match::coarseRange(wide, layout, match::rawThreshold(n, 80.f), 0);
  EXPECT_LT(range.columns, layout.cells_x / 2);
  EXPECT_LT(range.rows, layout.cells_y / 2);
  EXPECT_GT(range.columns * range.rows, 0);
  const auto credited = match::coarseRange(wide, layout, match::rawThreshold(n, 80.f), MatchParams{}.outside_response);
  EXPECT_GT(credited.columns, range.columns);
  EXPECT_LT(credited.columns, layout.cells_x);
  EXPECT_LT(credited.rows, layout.cells_y);
}

}  // namespace
}  // namespace vkpose
