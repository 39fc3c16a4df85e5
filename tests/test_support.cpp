#include "tests/test_support.hpp"

#include <filesystem>
#include <random>

#include "vkpose/error.hpp"
#include "vkpose/frame_io.hpp"
#include "vkpose/opencv_linemod.hpp"

namespace vkpose::test {

std::string sharedData() { return VKPOSE_SHARED_DATA_DIR; }

bool haveSharedData() { return std::filesystem::exists(sharedData() + "/lmo_scene2_frame3/test/000002/rgb/000003.png"); }

LinemodFrame lmoFrame() {
  const std::string d = sharedData() + "/lmo_scene2_frame3/test/000002/";
  return loadFrame(d + "rgb/000003.png", d + "depth/000003.png");
}

LinemodFrame icbinFrame() {
  const std::string d = sharedData() + "/icbin/scene2/";
  return loadFrame(d + "rgb/0000.png", d + "depth/0000.png");
}

std::vector<LinemodTemplate> templatesFrom(const LinemodFrame& frame, const FeatureParams& params, int count,
                                           unsigned seed) {
  std::mt19937 rng(seed);
  std::vector<cv::Rect> regions;
  std::uniform_int_distribution<int> size(40, 150);
  for (int i = 0; i < count * 2; ++i) {
    const int w = std::min(size(rng), frame.bgr.cols), h = std::min(size(rng), frame.bgr.rows);
    std::uniform_int_distribution<int> x(0, frame.bgr.cols - w), y(0, frame.bgr.rows - h);
    regions.emplace_back(x(rng), y(rng), w, h);
  }
  auto detector = makeOpenCvDetector(params);
  auto templates = extractOpenCvTemplates(*detector, frame, regions, params);
  if (templates.size() > static_cast<std::size_t>(count)) templates.resize(static_cast<std::size_t>(count));
  return templates;
}

GpuContext& context() {
  static GpuContext ctx;
  return ctx;
}

std::string inputErrorOf(const std::function<void()>& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  ADD_FAILURE() << "no InputError";
  return {};
}

}  // namespace vkpose::test
