// `vkpose bench match`: vkpose against cv::linemod on the same frame and templates.
#include <filesystem>
#include <fstream>
#include <unistd.h>

#include <fmt/core.h>
#include <nlohmann/json.hpp>

#include "bench/bench_support.hpp"
#include "bench/match_benchmark.hpp"
#include "cli/commands.hpp"
#include "vkpose/error.hpp"

namespace vkpose::cli {

namespace {

/// The rows as a table on stdout, and as the JSON array `--json` writes.
nlohmann::json printMatchRows(const std::vector<bench::MatchBenchRow>& rows) {
  fmt::print("{:>7}  {:>9}  {:>11}  {:>11}  {:>6}  {:>9}  {:>9}  {:>6}  {:>10}  {:>10}  {:>10}\n", "objects",
             "templates", "vkpose ms", "opencv ms", "ratio", "matches", "opencv", "passes", "GPU peak", "RSS",
             "peak RSS");
  nlohmann::json out = nlohmann::json::array();
  for (const auto& r : rows) {
    fmt::print("{:>7}  {:>9}  {:>11.1f}  {:>11}  {:>6}  {:>9}  {:>9}  {:>6}  {:>10}  {:>10}  {:>10}\n",
               r.objects > 0 ? std::to_string(r.objects) : "-", r.templates, r.vkpose_ms,
               r.opencv_ms > 0 ? fmt::format("{:.1f}", r.opencv_ms) : "-",
               r.opencv_ms > 0 ? fmt::format("{:.2f}", r.ratio) : "-", r.vkpose_matches,
               r.opencv_ms > 0 ? std::to_string(r.opencv_matches) : "-",
               r.attempts > r.passes ? fmt::format("{}/{}", r.passes, r.attempts) : std::to_string(r.passes),
               bench::formatBytes(r.gpu_peak_bytes), bench::formatBytes(r.rss_bytes),
               bench::formatBytes(r.peak_rss_bytes));
    nlohmann::json row = {{"templates", r.templates},
                          {"device", r.device},
                          {"vkpose_ms", r.vkpose_ms},
                          {"vkpose_matches", r.vkpose_matches},
                          {"passes", r.passes},
                          {"attempts", r.attempts},
                          {"coarse_candidates", r.coarse_candidates},
                          {"gpu_peak_bytes", r.gpu_peak_bytes},
                          {"rss_bytes", r.rss_bytes},
                          {"peak_rss_bytes", r.peak_rss_bytes}};
    nlohmann::json stages = nlohmann::json::object();
    for (const auto& st : r.stages)
      stages[st.name] = {{"mean_ms", st.ms}, {"kernel_ms", st.kernel_ms}, {"host_ms", st.ms - st.kernel_ms}};
    row["stages"] = stages;
    if (r.objects > 0) row["objects"] = r.objects;
    if (r.opencv_ms > 0) {
      row["opencv_ms"] = r.opencv_ms;
      row["ratio"] = r.ratio;
      row["opencv_matches"] = r.opencv_matches;
    }
    out.push_back(row);
  }
  // Where each row's time goes: the GPU's own time (device timestamps) and the host's rest.
  fmt::print("\n{:>9}  {:>26}  {:>26}  {:>14}\n", "templates", "features ms (kernel/host)",
             "similarity ms (kernel/host)", "readback ms");
  for (const auto& r : rows) {
    std::string cells;
    for (const auto& st : r.stages)
      cells += st.name == stageName(Stage::match_readback)
                   ? fmt::format("  {:>14.1f}", st.ms)
                   : fmt::format("  {:>26}", fmt::format("{:.1f} ({:.1f}/{:.1f})", st.ms, st.kernel_ms, st.ms - st.kernel_ms));
    fmt::print("{:>9}{}\n", r.templates, cells);
  }
  return out;
}

/// `vkpose bench match`.
ExitCode runBenchMatch(bench::MatchBenchOptions options, const std::string& json_path, const std::string& sweep,
                       bool templates_given, const GlobalOptions& global) {
  if (options.rgb.empty() != options.depth.empty()) throw InputError("--rgb and --depth go together");
  if (!json_path.empty() && std::ifstream(json_path).good())
    throw InputError("'" + json_path + "' exists; vkpose does not overwrite results (remove it first)");
  std::string svg_path;
  if (!sweep.empty()) {
    if (json_path.empty()) throw InputError("--sweep writes its JSON and an SVG plot next to it: give --json FILE");
    svg_path = std::filesystem::path(json_path).replace_extension(".svg").string();
    if (std::filesystem::exists(svg_path))
      throw InputError("'" + svg_path + "' exists; vkpose does not overwrite results (remove it first)");
    if (sweep == "templates") {
      options.sweep = bench::MatchSweep::Templates;
      if (!templates_given) options.template_counts = bench::templateSweepCounts();
    } else {
      options.sweep = bench::MatchSweep::Objects;
    }
  } else if (!options.bank.empty()) {
    throw InputError("--bank is for --sweep objects");
  }
  options.progress = !global.quiet && isatty(STDERR_FILENO);
  std::string frame;
  const auto rows = bench::runMatchBenchmark(options, global.gpu(), frame);
  fmt::print("LINEMOD matching, both modalities, T = {{5, 8}}, threshold {} %, median of {} runs\n",
             options.threshold, options.repeats);
  fmt::print("frame: {}\n\n", frame);
  fmt::print("device: {}\n\n", rows.empty() ? "" : rows.front().device);
  const nlohmann::json out = printMatchRows(rows);
  fmt::print("(passes: similarity passes, /submits when some overflowed and ran again; GPU peak: our GPU buffers at "
             "most at once; RSS: resident after vkpose's runs; peak RSS: the process so far)\n");
  bench::printKernelProfile();
  if (!json_path.empty()) {
    std::ofstream f(json_path);
    if (!f) throw InputError("cannot write '" + json_path + "'");
    f << out.dump(2) << "\n";
    if (!svg_path.empty()) {
      std::ofstream(svg_path) << bench::matchSweepSvg(rows, frame);
      if (!global.quiet) fmt::print("wrote {} and {}\n", json_path, svg_path);
    }
  }
  return kOk;
}

}  // namespace

Runner addBenchCommand(CLI::App& app, const GlobalOptions& global) {
  auto* bench = app.add_subcommand("bench", "Throughput benchmarks");
  bench->require_subcommand(1);
  const Runner train = addBenchTrainCommand(*bench, global);
  auto* train_command = bench->get_subcommand("train");
  const Runner detect = addBenchDetectCommand(*bench, global);
  auto* detect_command = bench->get_subcommand("detect");
  addBenchSoakCommand(*bench, global);  // runs in its parse callback
  auto* soak_command = bench->get_subcommand("soak");
  auto* match = bench->add_subcommand("match", "LINEMOD matching: vkpose vs OpenCV's cv::linemod, same templates");
  auto options = std::make_shared<bench::MatchBenchOptions>();
  auto json_path = std::make_shared<std::string>();
  auto* templates_option =
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
  auto sweep = std::make_shared<std::string>();
  match->add_option("--sweep", *sweep,
                    "templates: 1,000 to 100,000 templates (--templates overrides the counts); objects: 1 to 20 "
                    "objects of --templates-per-object each (--objects overrides the counts); needs --json, the "
                    "plot goes next to it as .svg")
      ->check(CLI::IsMember({"templates", "objects"}));
  match->add_option("--objects", options->object_counts, "Object counts of the objects sweep (comma separated)")
      ->delimiter(',')
      ->check(CLI::Range(1, 1000))
      ->capture_default_str();
  match->add_option("--templates-per-object", options->templates_per_object,
                    "Templates per object in the objects sweep (without --bank)")
      ->check(CLI::Range(1, 1000000))
      ->capture_default_str();
  match->add_option("--bank", options->bank,
                    "Objects sweep: each object is a copy of this bank's templates (default: templates cut from the "
                    "frame)");
  match->add_option("--json", *json_path, "Write the results as JSON to this file (never overwritten)");
  return [options, json_path, sweep, templates_option, train, train_command, detect, detect_command, soak_command,
          &global]() {
    if (train_command->parsed()) return train();
    if (detect_command->parsed()) return detect();
    if (soak_command->parsed()) return static_cast<int>(kOk);  // it ran (and passed) inside parse()
    return static_cast<int>(runBenchMatch(*options, *json_path, *sweep, templates_option->count() > 0, global));
  };
}

}  // namespace vkpose::cli
