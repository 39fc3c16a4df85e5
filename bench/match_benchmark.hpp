#pragma once
// `vkpose bench match`: LINEMOD matching (stages 1 and 2) by vkpose and by OpenCV's
// cv::linemod on the same frame, with the same templates and threshold, in the same run.
#include <string>
#include <vector>

#include "vkpose/device.hpp"

namespace vkpose::bench {

/// What a run varies: the template counts given, the templates sweep (1,000 to 100,000) or
/// the objects sweep (1 to 20 objects of templates_per_object templates each).
enum class MatchSweep { None, Templates, Objects };

struct MatchBenchOptions {
  std::vector<int> template_counts = {1000, 3000, 14040};
  MatchSweep sweep = MatchSweep::None;
  std::vector<int> object_counts = {1, 2, 5, 10, 20};  ///< the objects sweep
  int templates_per_object = 14040;                    ///< the objects sweep, without a bank
  /// The objects sweep: each object is a copy of this bank's templates (empty: templates cut
  /// from the frame, templates_per_object each).
  std::string bank;
  int repeats = 5;          ///< timed runs per count (after one warm-up); the median is reported
  float threshold = 80.0f;  ///< percent
  std::string rgb, depth;   ///< frame; empty: the LM-O frame from ../shared/data, else synthetic
  bool run_opencv = true;
  bool progress = true;
};

struct MatchBenchRow {
  int templates = 0;
  int objects = 0;  ///< the objects sweep; 0 otherwise
  std::string device;
  double vkpose_ms = 0, opencv_ms = 0, ratio = 0;
  std::size_t vkpose_matches = 0, opencv_matches = 0;
  std::size_t passes = 0;            ///< similarity passes per frame (MatchTimings::passes)
  std::size_t attempts = 0;          ///< similarity submits per frame, overflowed ones included
  std::size_t coarse_candidates = 0;
  /// vkpose's stages, mean of the timed runs: wall ms and, of it, the GPU's own time (device
  /// timestamps; 0 where the queue writes none). The rest is the host's.
  struct Stage {
    std::string name;
    double ms = 0, kernel_ms = 0;
  };
  std::vector<Stage> stages;  ///< features, similarity, match_readback
  std::size_t gpu_peak_bytes = 0;    ///< the most our GPU buffers held at once during this row
  std::size_t rss_bytes = 0;         ///< resident memory after vkpose's runs (templates, matcher)
  std::size_t peak_rss_bytes = 0;    ///< the process's peak resident memory after this row
};

/// The template sweep's counts: 1,000 to 100,000.
std::vector<int> templateSweepCounts();

/// The rows as an SVG plot: median ms of vkpose and cv::linemod over templates (or objects),
/// both axes logarithmic.
std::string matchSweepSvg(const std::vector<MatchBenchRow>& rows, const std::string& frame_description);

std::vector<MatchBenchRow> runMatchBenchmark(const MatchBenchOptions& options, const GpuOptions& gpu,
                                             std::string& frame_description);

}  // namespace vkpose::bench
