// vkpose's matcher against OpenCV's cv::linemod::Detector::match on the same 640x480 frames
// with the same templates (cut by OpenCV's own extraction and imported).
//
// Differences allowed, by name:
//  - BorderClampAndWrap: OpenCV clamps refinement windows to 8*T pixels from the image
//    border and lets coarse templates wrap from the right edge into the next row; vkpose
//    neither clamps nor wraps (it scores templates partly outside the image against zeros).
//    So matches within that band of the border may differ; every other match must be equal.
//  - UniqueIgnoresTemplateId: OpenCV's final std::unique compares x, y, similarity and class
//    but not the template id, so of two templates refined to the same spot with the same
//    similarity it may keep only one.
#include <set>
#include <tuple>

#include <opencv2/rgbd/linemod.hpp>

#include "match/features.hpp"
#include "match/matcher.hpp"
#include "match/opencv_linemod.hpp"
#include "test_support.hpp"
#include "training/training.hpp"
#include "vkpose/bank.hpp"

namespace vkpose {
namespace {

/// Hands precomputed label images to OpenCV, so its matching runs on exactly vkpose's
/// quantization.
class FixedPyramid : public cv::linemod::QuantizedPyramid {
 public:
  explicit FixedPyramid(std::vector<cv::Mat> levels) : levels_(std::move(levels)) {}
  void quantize(cv::Mat& dst) const override { levels_[level_].copyTo(dst); }
  bool extractTemplate(cv::linemod::Template&) const override { return false; }
  void pyrDown() override { ++level_; }

 private:
  std::vector<cv::Mat> levels_;
  std::size_t level_ = 0;
};

class FixedModality : public cv::linemod::Modality {
 public:
  explicit FixedModality(std::vector<cv::Mat> levels) : levels_(std::move(levels)) {}
  cv::String name() const override { return "Fixed"; }
  void read(const cv::FileNode&) override {}
  void write(cv::FileStorage&) const override {}

 protected:
  cv::Ptr<cv::linemod::QuantizedPyramid> processImpl(const cv::Mat&, const cv::Mat&) const override {
    return cv::makePtr<FixedPyramid>(levels_);
  }

 private:
  std::vector<cv::Mat> levels_;
};

using Key = std::tuple<int, int, int, float>;
Key key(const Match& m) { return {m.template_id, m.x, m.y, m.similarity}; }

struct Comparison {
  int interior_equal = 0, border_differences = 0, unique_differences = 0;
};

Comparison compare(const std::vector<Match>& ours, const std::vector<cv::linemod::Match>& theirs_cv,
                   const std::vector<LinemodTemplate>& templates, cv::Size size) {
  std::set<Key> a, b;
  for (const auto& m : ours) a.insert(key(m));
  for (const auto& m : theirs_cv) b.insert(key(fromOpenCvMatch(m)));
  std::set<std::tuple<int, int, float>> opencv_spots;
  for (const auto& k : b) opencv_spots.insert({std::get<1>(k), std::get<2>(k), std::get<3>(k)});
  // BorderClampAndWrap band: the clamp (8 * T0 = 40 px) plus a refinement window (8 cells
  // of 5 px) plus the coarse wrap (a template's full width at the right / bottom).
  auto interior = [&](const Key& k) {
    const auto& level = templates[static_cast<std::size_t>(std::get<0>(k))].levels[0];
    const int band = 40 + 45;
    const int x = std::get<1>(k), y = std::get<2>(k);
    return x >= band && y >= band && x <= size.width - level.width - band && y <= size.height - level.height - band;
  };
  Comparison c;
  for (const auto& k : a) {
    if (b.count(k)) {
      if (interior(k)) ++c.interior_equal;
      continue;
    }
    if (!interior(k)) {
      ++c.border_differences;
    } else if (opencv_spots.count({std::get<1>(k), std::get<2>(k), std::get<3>(k)})) {
      ++c.unique_differences;
    } else {
      ADD_FAILURE() << "vkpose match not in OpenCV's, unexplained: template " << std::get<0>(k) << " at ("
                    << std::get<1>(k) << ", " << std::get<2>(k) << ") " << std::get<3>(k) << " %";
    }
  }
  for (const auto& k : b)
    if (!a.count(k)) {
      if (!interior(k))
        ++c.border_differences;
      else
        ADD_FAILURE() << "OpenCV match not in vkpose's, unexplained: template " << std::get<0>(k) << " at ("
                      << std::get<1>(k) << ", " << std::get<2>(k) << ") " << std::get<3>(k) << " %";
    }
  return c;
}

/// vkpose's GPU matches of `templates` on `frame` at 80 %, the threshold both sides use.
constexpr float kThreshold = 80.0f;
std::vector<Match> vkposeMatches(const LinemodFrame& frame, const FeatureParams& params,
                                 const std::vector<LinemodTemplate>& templates) {
  LinemodMatcher matcher(test::context(), params, MatchParams{kThreshold});
  matcher.setTemplates(templates);
  return matcher.match(frame);
}

void expectSameMatchesOnSharedQuantization(const LinemodFrame& frame, const std::string& name) {
  const FeatureParams params;
  const auto templates = test::templatesFrom(frame, params, 120, 3);
  ASSERT_GT(templates.size(), 50u);
  const auto ours = vkposeMatches(frame, params, templates);

  const auto pyramid = quantizeFramePyramid(frame, params);
  std::vector<cv::Ptr<cv::linemod::Modality>> modalities;
  for (int m = 0; m < kModalityCount; ++m)
    modalities.push_back(cv::makePtr<FixedModality>(std::vector<cv::Mat>{pyramid[0].labels[m], pyramid[1].labels[m]}));
  cv::linemod::Detector detector(modalities, params.T);
  for (const auto& t : templates)
    detector.addSyntheticTemplate(toOpenCvTemplate(t, activeModalities(params)), "parity");
  std::vector<cv::linemod::Match> theirs;
  detector.match({frame.bgr, frame.depth_mm}, kThreshold, theirs);

  const auto c = compare(ours, theirs, templates, frame.bgr.size());
  EXPECT_GT(c.interior_equal, 20) << name;
  std::cout << "[ opencv  ] " << name << ": " << ours.size() << " vkpose matches, " << theirs.size()
            << " OpenCV; equal away from the border: " << c.interior_equal
            << "; BorderClampAndWrap: " << c.border_differences << "; UniqueIgnoresTemplateId: " << c.unique_differences
            << "\n";
}

TEST(OpenCvParity, MatchesOnSharedQuantizationLmo) {
  expectSameMatchesOnSharedQuantization(test::lmoFrameOrStandIn(), test::frameName("LM-O"));
}

TEST(OpenCvParity, MatchesOnSharedQuantizationIcbin) {
  expectSameMatchesOnSharedQuantization(test::icbinFrameOrStandIn(), test::frameName("IC-BIN"));
}

// LINE-2D (colour only) end to end, OpenCV computing its own features: the quantization
// differs only at fastAtan2 bin edges (see features_reference_test), so matches agree except
// at the border and where such a pixel changes a response.
TEST(OpenCvParity, ColourOnlyEndToEndWithOpenCvsOwnFeatures) {
  const auto frame = test::lmoFrameOrStandIn();
  FeatureParams params;
  params.use_depth = false;
  const auto templates = test::templatesFrom(frame, params, 120, 5);
  ASSERT_GT(templates.size(), 50u);
  const auto ours = vkposeMatches(frame, params, templates);
  auto detector = makeOpenCvDetector(params);
  for (const auto& t : templates) detector->addSyntheticTemplate(toOpenCvTemplate(t, activeModalities(params)), "p");
  std::vector<cv::linemod::Match> theirs;
  detector->match({frame.bgr}, kThreshold, theirs);
  const auto c = compare(ours, theirs, templates, frame.bgr.size());
  EXPECT_GT(c.interior_equal, 20);
  std::cout << "[ opencv  ] LINE colour only: " << ours.size() << " vkpose, " << theirs.size()
            << " OpenCV; equal away from the border: " << c.interior_equal << "\n";
}

}  // namespace
}  // namespace vkpose
