#pragma once
// `vkpose bench train`: templates per second of vkpose's training (GPU rendering + feature
// selection) and, on the same renderings, OpenCV's cv::linemod::Detector::addTemplate.
#include <string>

#include "vkpose/device.hpp"

namespace vkpose::bench {

struct TrainBenchOptions {
  std::string mesh;           ///< empty: ../shared/data/meshes/coffee_cup.stl, else an icosphere
  int viewpoints = 216;       ///< the paper's sampling: 216 x 5 radii x 13 in-plane = 14,040
  int opencv_templates = 200; ///< renderings that OpenCV's training is timed on
  bool progress = true;
  /// Also train with the CPU reference quantization (training before the GPU did it).
  bool reference = true;
};

struct TrainBenchResult {
  std::string mesh, device;
  std::size_t templates = 0;
  double total_s = 0, render_s = 0, features_s = 0, templates_per_s = 0;
  /// Per template, on the same renderings: vkpose's feature selection and OpenCV's training.
  double vkpose_features_ms = 0, opencv_ms = 0, ratio = 0;
  std::size_t opencv_templates = 0, opencv_refused = 0;
  /// The run with CPU quantization (options.reference): its times, and whether it made the
  /// same templates.
  double reference_total_s = 0, reference_features_s = 0;
  bool reference_identical = false;
};

TrainBenchResult runTrainBenchmark(const TrainBenchOptions& options, const GpuOptions& gpu);

}  // namespace vkpose::bench
