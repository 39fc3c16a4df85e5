// `vkpose bench detect`: the whole detector over N frames, per-stage times, memory, and
// cv::linemod on the same frames as the baseline of stages 1-2.
#include <filesystem>
#include <memory>

#include <fmt/core.h>
#include <nlohmann/json.hpp>

#include "bench/bench_support.hpp"
#include "bench/detect_benchmark.hpp"
#include "cli/commands.hpp"
#include "util/progress.hpp"
#include "vkpose/detector.hpp"
#include "vkpose/error.hpp"

namespace vkpose::cli {

using util::ProgressBar;

Runner addBenchDetectCommand(CLI::App& bench, const GlobalOptions& global) {
  auto* sub = bench.add_subcommand(
      "detect", "The whole detector (stages 1-8) over N frames: per-stage median and p95 ms, frames/s, memory, "
                "and cv::linemod on the same frames");
  auto options = std::make_shared<bench::DetectBenchOptions>();
  auto json_path = std::make_shared<std::string>();
  auto source = std::make_shared<std::string>("auto");
  sub->add_option("--bank", options->banks, "Template bank (.vkpb); repeat for several objects")->required();
  sub->add_option("--frames", options->frames, "Frames to time (real frames are cycled when there are fewer)")
      ->capture_default_str();
  sub->add_option("--warmup", options->warmup,
                  "Untimed frames first (template upload, the driver's first-use compilation)")
      ->capture_default_str();
  sub->add_option("--source", *source,
                  "Frames: auto (LM-O's frame for LM-O banks, IC-BIN's for the cup or juice carton, synthetic "
                  "scenes of the banks' meshes otherwise or without ../shared/data), lmo, icbin, synthetic")
      ->capture_default_str();
  sub->add_option("--data", options->data_dir, "Folder of the real frames (default: ../shared/data)");
  sub->add_option("--seed", options->seed, "Seed of the synthetic frames")->capture_default_str();
  sub->add_option("--threshold", options->params.match.threshold, "Match threshold, percent (both vkpose and cv::linemod)")
      ->check(CLI::Range(1.0, 100.0))
      ->capture_default_str();
  sub->add_flag("!--no-pose", options->params.estimate_poses, "Stop after NMS (stages 1-5 only)");
  sub->add_flag("!--no-opencv", options->run_opencv, "Skip the cv::linemod baseline");
  sub->add_flag("!--no-depth-pruning", options->params.match.depth_pruning,
                "Score every template at every position (the matcher before depth-guided pruning), to compare");
  sub->add_flag("!--no-in-flight", options->in_flight,
                "Skip the second run of the frames with two in flight (Detector::detectSequence)");
  sub->add_option("--json", *json_path, "Also write the figures as JSON to this file (never overwritten)");
  return [options, json_path, source, &global]() {
    options->source = bench::parseFrameSource(*source);
    if (!json_path->empty() && std::filesystem::exists(*json_path))
      throw InputError("'" + *json_path + "' exists; vkpose does not overwrite results (remove it first)");
    std::unique_ptr<ProgressBar> bar;
    std::string phase;
    const auto report = bench::runDetectBenchmark(
        *options, global.gpu(), [&](const std::string& now, std::size_t done, std::size_t total) {
          if (now != phase) {
            bar = std::make_unique<ProgressBar>(now, global.quiet);
            phase = now;
          }
          bar->update(done, total);
        });
    bar.reset();
    for (const auto& w : report.warnings) fmt::print(stderr, "vkpose: warning: {}\n", w);
    fmt::print("{}", bench::formatDetectReport(report));
    bench::printKernelProfile();
    if (!json_path->empty()) {
      writeTextFile(*json_path, bench::detectReportJson(report).dump(2) + "\n", false);
      if (!global.quiet) fmt::print("wrote {}\n", *json_path);
    }
    return kOk;
  };
}

}  // namespace vkpose::cli
