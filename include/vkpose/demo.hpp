#pragma once
// `vkpose demo`: the whole pipeline on an embedded default, with nothing but the repository. Three
// objects built in code (procedural_meshes.hpp) are piled standing in a bin (synth.hpp, with a
// structured-light sensor's noise), trained (banks cached between runs, bank_cache.hpp),
// detected (detector.hpp) and scored against the known poses (evaluation.hpp).
#include <functional>
#include <string>
#include <vector>

#include "vkpose/evaluation.hpp"
#include "vkpose/gpu_context.hpp"
#include "vkpose/views.hpp"

namespace vkpose {

struct DemoParams {
  std::string out_dir = "vkpose-demo";
  bool overwrite = false;  ///< replace out_dir's contents even when no earlier demo wrote it
  std::string cache_dir;   ///< where banks are cached; empty: no cache
  int images = 3;          ///< bin scenes
  uint32_t seed = 1;
  int min_instances = 2, max_instances = 2;  ///< of each object per scene
  /// Training views: the upper hemisphere's viewpoints within max_view_angle_deg of the top
  /// (the parts stand in the bin and the camera looks down), every in-plane turn.
  ViewSamplingParams views{216, false, {0.55f, 0.85f, 0.1f}, {-180.f, 170.f, 10.f}};
  float max_view_angle_deg = 40.f;
  DetectorParams detector;
};

/// InputError for parameters out of range (images < 1 or > 100, bad instance counts, ...).
void validateDemoParams(const DemoParams& params);

/// What each step reports as it goes, for the command line to print; every member may be empty.
struct DemoCallbacks {
  std::function<void(const std::string&)> step;                 ///< a step starts: "Training lidded_cup"
  std::function<void(std::size_t, std::size_t)> progress;       ///< within the step: (done, total)
  std::function<void(const std::string&)> info;                 ///< a line of detail
};

struct DemoObject {
  int obj_id = 0;
  std::string name, mesh_path, bank_path;
  std::size_t templates = 0;
  bool bank_from_cache = false;
  double train_s = 0;  ///< training (or reading the cached bank), seconds
};

struct DemoImageResult {
  int image_id = 0;
  std::string overlay_path, json_path;
  DetectionResult result;
};

struct DemoReport {
  std::string device;
  std::vector<DemoObject> objects;
  std::vector<DemoImageResult> images;
  EvalReport evaluation;
  int instances = 0;  ///< ground-truth instances in all scenes
  double synth_s = 0, train_s = 0, detect_s = 0, total_s = 0;
  std::string overlay_path, json_path, report_path;  ///< the first image's overlay and JSON, the score report
};

/// Runs the demo into params.out_dir: meshes/ (the objects, PLY), dataset/ (the bin scenes in
/// BOP format), overlays/ and detections/ (per image), overlay.png and detections.json (the
/// first image's, for a quick look), report.json (the scores) and results_vkpose.csv (BOP).
/// An out_dir that exists, is not empty and was not written by an earlier demo is an
/// InputError unless params.overwrite.
DemoReport runDemo(GpuContext& ctx, const DemoParams& params, const DemoCallbacks& callbacks = {});

}  // namespace vkpose
