// `vkpose bench match`: vkpose against cv::linemod on the same frame and templates.
#include <fstream>
#include <unistd.h>

#include <fmt/core.h>
#include <nlohmann/json.hpp>

#include "bench/match_benchmark.hpp"
#include "cli/commands.hpp"
#include "gpu/batch.hpp"
#include "vkpose/error.hpp"

namespace vkpose::cli {

Runner addBenchCommand(CLI::App& app, const GlobalOptions& global) {
  auto* bench = app.add_subcommand("bench", "Throughput benchmarks");
  bench->require_subcommand(1);
  addBenchTrainCommand(*bench, global);
  addBenchSoakCommand(*bench, global);
  auto* match = bench->add_subcommand("match", "LINEMOD matching: vkpose vs OpenCV's cv::linemod, same templates");
  auto options = std::make_shared<bench::MatchBenchOptions>();
  auto json_path = std::make_shared<std::string>();
  match->add_option("--templates", options->template_counts, "Template counts to time (comma separated)")
      ->delimiter(',')
      ->check(CLI::Range(1, 1000000))
      ->capture_default_str();
  match->add_option("--repeats", options->repeats, "Timed runs per count; the median is reported")
      ->check(CLI::Range(1, 1000))
      ->capture_default_str();
  match->add_option("--threshold", options->threshold, "Match threshold, percent")
      ->check(CLI::Range(1.0, 100.0))
      ->capture_default_str();
  match->add_option("--rgb", options->rgb, "Colour image (default: the LM-O frame in ../shared/data)");
  match->add_option("--depth", options->depth, "Depth image, 16-bit PNG in mm");
  match->add_flag("!--no-opencv", options->run_opencv, "Skip the cv::linemod baseline");
  match->add_option("--json", *json_path, "Write the results as JSON to this file");
  return [options, json_path, &global, match]() {
    if (!match->parsed()) return 0;  // another bench subcommand ran in its callback
    if (options->rgb.empty() != options->depth.empty()) throw InputError("--rgb and --depth go together");
    if (!json_path->empty() && std::ifstream(*json_path).good())
      throw InputError("'" + *json_path + "' exists; vkpose does not overwrite results (remove it first)");
    options->progress = !global.quiet && isatty(STDERR_FILENO);
    std::string frame;
    const auto rows = bench::runMatchBenchmark(*options, global.gpu(), frame);
    fmt::print("LINEMOD matching, both modalities, T = {{5, 8}}, threshold {} %, median of {} runs\n",
               options->threshold, options->repeats);
    fmt::print("frame: {}\n\n", frame);
    fmt::print("{:>10}  {:>12}  {:>12}  {:>7}  {:>9}  {:>9}  {}\n", "templates", "vkpose ms", "opencv ms", "ratio",
               "matches", "opencv", "device");
    nlohmann::json out = nlohmann::json::array();
    for (const auto& r : rows) {
      fmt::print("{:>10}  {:>12.2f}  {:>12.2f}  {:>7.2f}  {:>9}  {:>9}  {}\n", r.templates, r.vkpose_ms, r.opencv_ms,
                 r.ratio, r.vkpose_matches, r.opencv_matches, r.device);
      out.push_back({{"templates", r.templates},
                     {"device", r.device},
                     {"vkpose_ms", r.vkpose_ms},
                     {"opencv_ms", r.opencv_ms},
                     {"ratio", r.ratio},
                     {"vkpose_matches", r.vkpose_matches},
                     {"opencv_matches", r.opencv_matches}});
    }
    if (!gpu::kernelProfile().empty()) {
      fmt::print("\nper kernel, all runs (VKPOSE_PROFILE_KERNELS):\n");
      for (const auto& [name, ms] : gpu::kernelProfile()) fmt::print("  {:<24} {:10.2f} ms\n", name, ms);
    }
    if (!json_path->empty()) {
      std::ofstream f(*json_path);
      if (!f) throw InputError("cannot write '" + *json_path + "'");
      f << out.dump(2) << "\n";
    }
    return 0;
  };
}

}  // namespace vkpose::cli
