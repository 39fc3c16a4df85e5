#pragma once
// `vkpose bench match`: LINEMOD matching (stages 1 and 2) by vkpose and by OpenCV's
// cv::linemod on the same frame, with the same templates and threshold, in the same run.
#include <string>
#include <vector>

#include "vkpose/gpu_context.hpp"

namespace vkpose::bench {

struct MatchBenchOptions {
  std::vector<int> template_counts = {1000, 3000, 14040};
  int repeats = 5;          ///< timed runs per count (after one warm-up); the median is reported
  float threshold = 80.0f;  ///< percent
  std::string rgb, depth;   ///< frame; empty: the LM-O frame from ../shared/data, else synthetic
  bool run_opencv = true;
  bool progress = true;
};

struct MatchBenchRow {
  int templates = 0;
  std::string device;
  double vkpose_ms = 0, opencv_ms = 0, ratio = 0;
  std::size_t vkpose_matches = 0, opencv_matches = 0;
};

std::vector<MatchBenchRow> runMatchBenchmark(const MatchBenchOptions& options, const GpuOptions& gpu,
                                             std::string& frame_description);

}  // namespace vkpose::bench
