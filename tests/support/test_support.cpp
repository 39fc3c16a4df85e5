#include "test_support.hpp"

#include <cstdlib>
#include <filesystem>
#include <memory>
#include <random>
#include <stdexcept>

#include <unistd.h>

#include "match/features.hpp"
#include "match/matcher.hpp"
#include "match/opencv_linemod.hpp"
#include "vkpose/bank.hpp"
#include "vkpose/device.hpp"
#include "vkpose/error.hpp"
#include "vkpose/frame.hpp"
#include "vkpose/geometry.hpp"
#include "vkpose/synth.hpp"
#include "synth/procedural_meshes.hpp"

namespace vkpose::test {

// VKPOSE_TEST_SHARED_DATA overrides the compiled-in folder, so that a run with the data on
// disk can still play a newcomer without it (VKPOSE_TEST_SHARED_DATA=/nonexistent).
std::string sharedData() {
  if (const char* dir = std::getenv("VKPOSE_TEST_SHARED_DATA"); dir && *dir) return dir;
  return VKPOSE_SHARED_DATA_DIR;
}

TemplateBank cachedBank(const Mesh& mesh, const TrainingParams& params) {
  return loadOrTrainBank(context(), mesh, params, sampleViews(params.views, mesh.bboxCentre()), VKPOSE_TEST_CACHE_DIR)
      .bank;
}

namespace {
/// The scratch folders made by this process, removed at its exit.
struct ScratchFolders {
  std::vector<std::filesystem::path> made;
  ~ScratchFolders() {
    for (const auto& dir : made) {
      std::error_code ignored;  // a folder already gone is fine
      std::filesystem::remove_all(dir, ignored);
    }
  }
};
}  // namespace

std::string scratchDir(const std::string& prefix) {
  static ScratchFolders folders;
  const auto dir = std::filesystem::temp_directory_path() / (prefix + std::to_string(::getpid()));
  if (std::filesystem::create_directories(dir)) folders.made.push_back(dir);
  return dir.string();
}

bool haveSharedData() { return std::filesystem::exists(sharedData() + "/lmo_scene2_frame3/test/000002/rgb/000003.png"); }

LinemodFrame lmoFrame() {
  const std::string d = sharedData() + "/lmo_scene2_frame3/test/000002/";
  return loadFrame(d + "rgb/000003.png", d + "depth/000003.png");
}

LinemodFrame icbinFrame() {
  const std::string d = sharedData() + "/icbin/scene2/";
  return loadFrame(d + "rgb/0000.png", d + "depth/0000.png");
}

namespace {

/// A frame of vkpose's own synthetic data: the demo's objects (a few instances each) and
/// clutter, with the sensor's noise; the same frame on every run.
LinemodFrame syntheticFrame(Layout layout, uint32_t seed) {
  static const std::vector<Mesh> objects = demoMeshes();
  SynthParams params;
  params.seed = seed;
  params.min_instances = 2;
  params.max_instances = 3;
  params.clutter = 6;
  params.placement.layout = layout;
  return synthesizeImage(context(), params, objects, 0).frame;
}

}  // namespace

LinemodFrame lmoFrameOrStandIn() {
  if (haveSharedData()) return lmoFrame();
  static const LinemodFrame frame = syntheticFrame(Layout::Bin, 7);
  return {frame.bgr.clone(), frame.depth_mm.clone()};
}

LinemodFrame icbinFrameOrStandIn() {
  if (haveSharedData()) return icbinFrame();
  static const LinemodFrame frame = syntheticFrame(Layout::Table, 8);
  return {frame.bgr.clone(), frame.depth_mm.clone()};
}

std::string frameName(const std::string& name) {
  return haveSharedData() ? name : name + "'s synthetic stand-in";
}

Mesh meshOrStandIn(const std::string& path, MeshUnits units) {
  if (haveSharedData()) return loadMesh(sharedData() + "/" + path, units);
  if (path.find("coffee_cup") != std::string::npos) return liddedCupMesh();
  if (path.find("juicecarton") != std::string::npos || path.find("milk") != std::string::npos ||
      path.find("obj_000005") != std::string::npos)
    return gableCartonMesh();
  throw std::logic_error("no stand-in for " + path);
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

namespace {

std::unique_ptr<GpuContext>& sharedContext() {
  static std::unique_ptr<GpuContext> ctx;
  return ctx;
}

/// Fails the test during which a Vulkan validation error was reported (the release tests run
/// with VKPOSE_VALIDATION=1, see tests/CMakeLists.txt); the layer's messages are on stderr.
class ValidationListener : public ::testing::EmptyTestEventListener {
  uint32_t before_ = 0;
  void OnTestStart(const ::testing::TestInfo&) override { before_ = GpuContext::processValidationErrors(); }
  void OnTestEnd(const ::testing::TestInfo& info) override {
    // OnTestEnd runs while the test is still the current one: the failure is recorded on it.
    if (const uint32_t n = GpuContext::processValidationErrors() - before_; n > 0)
      ADD_FAILURE() << n << " Vulkan validation error(s) during " << info.test_suite_name() << "." << info.name()
                    << " (the layer's messages are above)";
  }
};

/// Destroys the shared context before the test program ends, so that validation errors of
/// the tear-down (objects left alive) fail the run too.
class ContextEnvironment : public ::testing::Environment {
  void TearDown() override {
    const uint32_t before = GpuContext::processValidationErrors();
    sharedContext().reset();
    if (const uint32_t n = GpuContext::processValidationErrors() - before; n > 0)
      ADD_FAILURE() << n << " Vulkan validation error(s) while destroying the shared context";
  }
};

[[maybe_unused]] const bool kRegistered = [] {
  ::testing::UnitTest::GetInstance()->listeners().Append(new ValidationListener);
  ::testing::AddGlobalTestEnvironment(new ContextEnvironment);
  return true;
}();

}  // namespace

GpuContext& context() {
  auto& ctx = sharedContext();
  if (!ctx) ctx = std::make_unique<GpuContext>();
  return *ctx;
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

void expectInputError(const std::function<void()>& f, std::initializer_list<std::string> parts) {
  const std::string message = inputErrorOf(f);
  for (const auto& p : parts) EXPECT_NE(message.find(p), std::string::npos) << "'" << p << "' missing from: " << message;
}

}  // namespace vkpose::test
