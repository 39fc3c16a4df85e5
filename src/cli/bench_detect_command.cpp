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

namespace {

/// `bench detect --sweep`: the frame time over object or instance counts, as JSON and an SVG plot.
ExitCode runSweep(const bench::DetectBenchOptions& options, const std::string& sweep, const std::vector<int>& counts,
             const std::string& json_path, const GlobalOptions& global, const bench::BenchProgress& show,
             std::unique_ptr<ProgressBar>& bar) {
  if (json_path.empty()) throw InputError("--sweep writes its JSON and an SVG plot next to it: give --json FILE");
  const std::string svg_path = std::filesystem::path(json_path).replace_extension(".svg").string();
  if (std::filesystem::exists(svg_path))
    throw InputError("'" + svg_path + "' exists; vkpose does not overwrite results (remove it first)");
  const auto kind = sweep == "objects" ? bench::DetectSweep::Objects : bench::DetectSweep::Instances;
  const std::vector<int> n = !counts.empty() ? counts
                             : kind == bench::DetectSweep::Objects ? std::vector<int>{1, 3, 8, 20}
                                                                    : std::vector<int>{1, 2, 4, 8};
  const auto rows = bench::runDetectSweep(options, kind, n, global.gpu(), show);
  bar.reset();
  fmt::print("{}", bench::formatDetectSweep(rows, kind));
  writeTextFile(json_path, bench::detectSweepJson(rows, kind).dump(2) + "\n", false);
  writeTextFile(svg_path, bench::detectSweepSvg(rows, kind), false);
  if (!global.quiet) fmt::print("wrote {} and {}\n", json_path, svg_path);
  return kOk;
}

}  // namespace

Runner addBenchDetectCommand(CLI::App& bench, const GlobalOptions& global) {
  auto* sub = bench.add_subcommand(
      "detect", "The whole detector (stages 1-8) over N frames: per-stage median and p95 ms, frames/s, memory, "
                "and cv::linemod on the same frames");
  auto options = std::make_shared<bench::DetectBenchOptions>();
  auto json_path = std::make_shared<std::string>();
  auto source = std::make_shared<std::string>("auto");
  auto config = std::make_shared<std::string>();
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
  addParamFlag(sub, options->params, "--threshold", ", vkpose and cv::linemod");
  addParamFlag(sub, options->params, "--no-pose");
  addParamFlag(sub, options->params, "--threads");
  sub->add_flag("!--no-opencv", options->run_opencv, "Skip the cv::linemod baseline");
  sub->add_flag("--no-depth", options->no_depth,
                "Drop the frames' depth images: colour-only detection, stage times of that path (cv::linemod on "
                "colour gradients alone)");
  sub->add_flag("!--no-depth-pruning", options->params.match.depth_pruning,
                "Score every template at every position (the matcher before depth-guided pruning), to compare");
  sub->add_flag("!--no-in-flight", options->in_flight,
                "Skip the second run of the frames with two in flight (Detector::detectSequence)");
  sub->add_option("--instances", options->instances,
                  "Synthetic frames: instances of each bank's mesh per frame (0: 1 to 2)")
      ->check(CLI::Range(0, 50))
      ->capture_default_str();
  auto sweep = std::make_shared<std::string>();
  auto counts = std::make_shared<std::vector<int>>();
  sub->add_option("--sweep", *sweep,
                  "How the frame time grows: objects (the banks cycled to 1, 3, 8, 20 objects) or instances (1, 2, "
                  "4, 8 of each object per synthetic frame); --counts overrides the counts; needs --json, the plot "
                  "goes next to it as .svg")
      ->check(CLI::IsMember({"objects", "instances"}));
  sub->add_option("--counts", *counts, "Counts of the sweep (comma separated)")->delimiter(',')->check(CLI::Range(1, 100));
  sub->add_option("--json", *json_path, "Also write the figures as JSON to this file (never overwritten)");
  addConfigOption(sub, *config);
  return [options, json_path, source, sweep, counts, config, &global]() {
    options->source = bench::parseFrameSource(*source);
    options->params = withConfig(*config, options->params);
    if (!json_path->empty() && std::filesystem::exists(*json_path))
      throw InputError("'" + *json_path + "' exists; vkpose does not overwrite results (remove it first)");
    std::unique_ptr<ProgressBar> bar;
    std::string phase;
    auto show = [&](const std::string& now, std::size_t done, std::size_t total) {
      if (now != phase) {
        bar = std::make_unique<ProgressBar>(now, global.quiet);
        phase = now;
      }
      bar->update(done, total);
    };
    if (!sweep->empty()) return runSweep(*options, *sweep, *counts, *json_path, global, show, bar);
    if (!counts->empty()) throw InputError("--counts goes with --sweep");
    const auto report = bench::runDetectBenchmark(*options, global.gpu(), show);
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
