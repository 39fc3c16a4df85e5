#pragma once
// `vkpose bench detect`: the whole Detector pipeline (stages 1-8) over N frames, the time of
// each stage (median and p95), frames per second and memory; and cv::linemod matching the same
// templates on the same frames, the baseline of stages 1-2.
#include <cstddef>
#include <functional>
#include <string>
#include <vector>

#include <nlohmann/json_fwd.hpp>

#include "vkpose/detector.hpp"
#include "vkpose/device.hpp"

namespace vkpose::bench {

enum class FrameSource { Auto, Lmo, Icbin, Synthetic };

struct DetectBenchOptions {
  std::vector<std::string> banks;  ///< bank files (.vkpb)
  int frames = 5;                  ///< frames timed; real frames are cycled when there are fewer
  /// Frames run first and not timed (the template upload and the driver's first-use shader
  /// compilation fall into them); 0 times the first frame with them, upload apart.
  int warmup = 1;
  /// Auto: LM-O's frame when every bank is an LM-O object (obj_0000NN with its model in the
  /// data), IC-BIN's frames when every bank is the cup or the juice carton, synthetic frames of
  /// the banks' own meshes otherwise (and when ../shared/data is absent).
  FrameSource source = FrameSource::Auto;
  std::string data_dir;            ///< empty: ../shared/data as built in
  uint32_t seed = 1;               ///< synthetic frames
  int instances = 0;               ///< synthetic frames: instances of each mesh (0: 1 to 2)
  bool run_opencv = true;
  /// Also run the frames through Detector::detectSequence (two frames in flight) and report
  /// its frames/s next to the frame-by-frame figure.
  bool in_flight = true;
  /// Drop the frames' depth: colour-only detection (and cv::linemod on the colour modality).
  bool no_depth = false;
  DetectorParams params;
};

/// One stage's times over the frames, milliseconds.
struct StageStats {
  std::string stage;
  double median_ms = 0, p95_ms = 0, mean_ms = 0;
  /// Of mean_ms, the GPU's own time (device timestamps; 0 for CPU stages and where the queue
  /// writes none) and the rest, the host's: recording, submits, waits, readbacks, the CPU work.
  double kernel_ms = 0, host_ms = 0;
};

struct DetectBenchReport {
  std::string device;
  std::string frames_from;  ///< what the frames are
  int frames = 0, warmup = 0, distinct_frames = 0;
  std::vector<std::string> objects;
  std::size_t templates = 0;
  double upload_ms = 0;  ///< template upload on the first frame (warm-up or not), never in "total"
  /// In pipeline order: features, similarity (with the match readback), clustering, scoring,
  /// nms, initial_pose, mls, icp, verification (those that ran), then total.
  std::vector<StageStats> stages;
  double frames_per_s = 0;  ///< frames / sum of the frames' totals
  /// frames / wall time of the same frames through detectSequence (two frames in flight; 0
  /// when not run), and whether it found the same detections.
  double frames_per_s_in_flight = 0;
  bool in_flight_same_detections = true;
  double mean_matches = 0, mean_hypotheses = 0, mean_detections = 0;
  /// Stages 7-8's budget: candidates refined a frame, their CPU ms each (one core), and
  /// refined candidates per accepted detection.
  double mean_refined = 0, refine_ms_per_candidate = 0, refined_per_detection = 0;
  /// Stages 6-8 a frame (mean): wall ms, the process's CPU ms meanwhile (all threads), and the
  /// most threads their candidates ran on (DetectorParams::threads).
  double pose_wall_ms = 0, pose_cpu_ms = 0;
  unsigned pose_threads = 0;
  /// Depth-guided pruning over the timed frames: shares of the coarse pass's (template,
  /// position) pairs pruned, and skipped whole by the GPU (both 0 when off).
  double pruned_share = 0, skipped_share = 0;
  /// cv::linemod on the same frames with the same templates and threshold (0 when not run).
  double opencv_match_ms = 0;   ///< median per frame
  double vkpose_match_ms = 0;   ///< median per frame of features + similarity (with readback)
  double opencv_ratio = 0;      ///< opencv_match_ms / vkpose_match_ms
  std::size_t opencv_matches = 0;  ///< mean per frame
  std::size_t peak_rss_bytes = 0;  ///< the process's peak resident memory at the end
  std::size_t gpu_peak_bytes = 0;  ///< the most bytes our GPU buffers held at once
  std::size_t gpu_live_bytes = 0;  ///< what they hold after the run (the detector's buffers)
  std::vector<std::string> warnings;
};

/// (phase, done, total) as work goes on: "loading banks", "warm-up", "detect", "cv::linemod".
using BenchProgress = std::function<void(const std::string&, std::size_t, std::size_t)>;

/// Throws InputError for no bank, frames < 1, warmup < 0, a bank that cannot be read, or a source whose
/// data is missing.
DetectBenchReport runDetectBenchmark(const DetectBenchOptions& options, const GpuOptions& gpu,
                                     const BenchProgress& progress = {});

/// The stage table, the throughput, the baseline ratio and the memory, as printed.
std::string formatDetectReport(const DetectBenchReport& report);
nlohmann::json detectReportJson(const DetectBenchReport& report);

// ---- sweeps: how the frame time grows --------------------------------------------------

enum class DetectSweep { Objects, Instances };

/// One point of a sweep: medians over its frames.
struct DetectSweepRow {
  int objects = 0, instances = 0;  ///< instances: per object and synthetic frame (0: 1 to 2)
  std::size_t templates = 0;
  double total_ms = 0, match_ms = 0, pose_ms = 0;  ///< whole frame; stages 1-5; stages 6-8
  double matches = 0, detections = 0, pruned_share = 0;
  std::string device, frames_from;
};

/// Objects: the banks, cycled to each count (copies are objects of their own, as many banks
/// of one size would be), on the frames `options.source` picks. Instances: that many of each
/// bank's mesh per synthetic frame. Each point is a runDetectBenchmark of its own (no
/// cv::linemod, no frames in flight).
std::vector<DetectSweepRow> runDetectSweep(const DetectBenchOptions& options, DetectSweep sweep,
                                           const std::vector<int>& counts, const GpuOptions& gpu,
                                           const BenchProgress& progress = {});
std::string formatDetectSweep(const std::vector<DetectSweepRow>& rows, DetectSweep sweep);
nlohmann::json detectSweepJson(const std::vector<DetectSweepRow>& rows, DetectSweep sweep);
/// Median ms per frame against the count: the whole frame, stages 1-5 and stages 6-8.
std::string detectSweepSvg(const std::vector<DetectSweepRow>& rows, DetectSweep sweep);

/// "auto", "lmo", "icbin", "synthetic"; InputError for anything else.
FrameSource parseFrameSource(const std::string& name);

}  // namespace vkpose::bench
