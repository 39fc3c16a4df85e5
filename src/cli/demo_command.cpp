// `vkpose demo`: for now, what exists: the device, and LINEMOD matching on the GPU against
// cv::linemod on a frame (the LM-O frame when ../shared/data is there, else a synthetic one).
// The full bin-picking demo lands with issue 7.
#include <fmt/core.h>

#include "bench/match_benchmark.hpp"
#include "cli/commands.hpp"

namespace vkpose::cli {

Runner addDemoCommand(CLI::App& app, const GlobalOptions& global) {
  app.add_subcommand("demo", "Run what vkpose can do so far on an embedded default");
  return [&global]() {
    GpuContext ctx(global.gpu());
    fmt::print("vkpose demo: Vulkan device: {} ({})\n", ctx.device().name, ctx.device().type);
    fmt::print("Stages available so far: training (vkpose train MESH --out BANK), frame features and LINEMOD "
               "matching on the GPU (stages 0-2).\n");
    bench::MatchBenchOptions o;
    o.template_counts = {500};
    o.repeats = 3;
    o.progress = false;
    std::string frame;
    const auto rows = bench::runMatchBenchmark(o, global.gpu(), frame);
    const auto& r = rows.front();
    fmt::print("Matched {} templates on {}:\n", r.templates, frame);
    fmt::print("  vkpose  {:8.2f} ms  {} matches\n", r.vkpose_ms, r.vkpose_matches);
    fmt::print("  OpenCV  {:8.2f} ms  {} matches  (cv::linemod, same templates)\n", r.opencv_ms, r.opencv_matches);
    fmt::print("Detection hypotheses, 6-DoF poses and the bin-picking demo follow (issues 4-7).\n");
    return 0;
  };
}

}  // namespace vkpose::cli
