// `vkpose demo [--out DIR]`: the README's main job. Three objects built in code are piled in a
// bin, trained (banks cached), detected and scored against the known poses; prints what it does
// and the results, and writes the overlay PNG and the detection JSON.
#include <algorithm>
#include <filesystem>

#include <fmt/core.h>

#include "bench/bench_support.hpp"
#include "cli/commands.hpp"
#include "util/progress.hpp"
#include "vkpose/bank.hpp"
#include "vkpose/detector.hpp"
#include "vkpose/evaluation.hpp"
#include "vkpose/picking.hpp"
#include "vkpose/synth.hpp"

namespace vkpose::cli {

using util::ProgressBar;

namespace {
struct DemoOptions {
  DemoParams params;
  std::string cache = defaultBankCacheDir(), config, write_meshes, write_parts;
  bool no_cache = false;
  bool pick = false;
};

void printDetections(const DemoImageResult& image) {
  fmt::print("  scene image {}: {} detection{}\n", image.image_id, image.result.detections.size(),
             image.result.detections.size() == 1 ? "" : "s");
  for (std::size_t i = 0; i < image.result.detections.size(); ++i) {
    const Detection& d = image.result.detections[i];
    fmt::print("    {:>2}  {:<14} score {:.2f}  t = ({:+.3f}, {:+.3f}, {:.3f}) m  ICP fitness {:.1f} mm2\n", i + 1,
               d.object, d.score, d.pose.t.x(), d.pose.t.y(), d.pose.t.z(), d.icp_fitness * 1e6);
  }
}

/// Median of each stage's time over the images, in pipeline order.
void printTimings(const std::vector<DemoImageResult>& images) {
  std::vector<std::pair<std::string, std::vector<double>>> stages;
  for (const auto& im : images)
    for (const auto& [stage, ms] : im.result.timings_ms) {
      auto it = std::find_if(stages.begin(), stages.end(), [&](const auto& s) { return s.first == stage; });
      if (it == stages.end()) it = stages.insert(stages.end(), {stage, {}});
      it->second.push_back(ms);
    }
  fmt::print("Detection time per image (median over {} image{}):\n", images.size(), images.size() == 1 ? "" : "s");
  std::string line;
  for (const auto& [stage, v] : stages) line += fmt::format("  {} {:.0f} ms", stage, bench::median(v));
  fmt::print("{}\n", line);
}
/// --pick: each scene's pick list, printed (the overlays with the picks drawn are written).
void printPicks(const DemoReport& report, const std::string& out_dir) {
  const std::vector<PickPlan> plans = planDemoPicks(report, out_dir);
  fmt::print("\nPick lists (suction on the middle of each face of a part's box; docs/picking.md):\n");
  for (std::size_t i = 0; i < plans.size(); ++i) {
    const DemoImageResult& image = report.images[i];
    fmt::print("  scene image {}: {} of {} detections can be picked\n", image.image_id, plans[i].picks.size(),
               image.result.detections.size());
    for (std::size_t k = 0; k < plans[i].picks.size(); ++k) {
      const Pick& p = plans[i].picks[k];
      fmt::print("    {}. {} (detection {}), grasp '{}', tilt {:.0f} deg, rank {:.2f}\n", k + 1,
                 image.result.detections[static_cast<std::size_t>(p.detection)].object, p.detection + 1, p.grasp.name,
                 p.grasp.tilt_deg, p.rank);
    }
  }
  if (!report.images.empty())
    fmt::print("Wrote {}_picks.png\n",
               std::filesystem::path(report.images.front().overlay_path).replace_extension().string());
}
}  // namespace

Runner addDemoCommand(CLI::App& app, const GlobalOptions& global) {
  auto opt = std::make_shared<DemoOptions>();
  auto& p = opt->params;
  auto* sub = app.add_subcommand(
      "demo",
      "Bin-picking demo on an embedded default: three objects built in code, piled in a synthetic bin with sensor "
      "noise, trained, detected and scored against the known poses");
  sub->add_option("--out", p.out_dir,
                  "Folder for the outputs (overlay.png, detections.json, report.json, the scenes and meshes); a "
                  "folder an earlier demo wrote is replaced")
      ->capture_default_str();
  sub->add_option("--images", p.images, "Bin scenes to render and solve")->check(CLI::Range(1, 100))->capture_default_str();
  sub->add_option("--seed", p.seed, "Seed of the scenes (the same seed gives the same scenes)")->capture_default_str();
  sub->add_option("--cache", opt->cache,
                  "Folder where trained banks are kept between runs (default: $VKPOSE_CACHE_DIR, else "
                  "$XDG_CACHE_HOME/vkpose/banks, else ~/.cache/vkpose/banks)")
      ->capture_default_str();
  sub->add_flag("--no-cache", opt->no_cache, "Train the banks again and do not keep them");
  addConfigOption(sub, opt->config);
  sub->add_flag("--force", p.overwrite, "Replace the demo's outputs in --out even if that folder holds other things");
  sub->add_flag("--pick", opt->pick,
                "Also plan the picks of each scene: where a suction cup takes each part, which part first "
                "(overlays/NNNNNN_picks.png)");
  sub->add_option("--write-meshes", opt->write_meshes,
                  "Only write the three objects as PLY (millimetres) into this folder and stop (assets/meshes is "
                  "made so); --force replaces files there");
  sub->add_option("--write-parts", opt->write_parts,
                  "Only write four small metal parts (a hex nut, a cap screw, a nozzle, a spark-plug key) as PLY "
                  "(millimetres) into this folder and stop (assets/parts is made so), for synth's piles; --force "
                  "replaces files there")
      ->excludes("--write-meshes");
  return [opt, &global]() {
    if (!opt->write_meshes.empty() || !opt->write_parts.empty()) {
      const bool parts = !opt->write_parts.empty();
      for (const std::string& path : parts ? writePartMeshes(opt->write_parts, opt->params.overwrite)
                                           : writeDemoMeshes(opt->write_meshes, opt->params.overwrite))
        if (!global.quiet) fmt::print("wrote {}\n", path);
      return 0;
    }
    DemoParams params = opt->params;
    params.cache_dir = opt->no_cache ? "" : opt->cache;
    params.detector = withConfig(opt->config, params.detector);
    GpuContext ctx(global.gpu());
    if (!global.quiet) fmt::print("vkpose demo on {} ({})\n", ctx.device().name, ctx.device().type);
    std::unique_ptr<ProgressBar> bar;
    int step_no = 0;
    DemoCallbacks callbacks;
    callbacks.step = [&](const std::string& what) {
      bar.reset();
      if (!global.quiet) fmt::print("[{}] {}\n", ++step_no, what);
      std::fflush(stdout);
      bar = std::make_unique<ProgressBar>("     ", global.quiet);
    };
    callbacks.progress = [&](std::size_t done, std::size_t total) {
      if (bar) bar->update(done, total);
    };
    callbacks.info = [&](const std::string& line) {
      if (bar) bar->finish();
      if (!global.quiet) fmt::print("     {}\n", line);
    };
    const DemoReport report = runDemo(ctx, params, callbacks);
    bar.reset();

    fmt::print("\nDetections (verified 6-DoF poses, camera frame):\n");
    for (const auto& image : report.images) printDetections(image);
    fmt::print("\nScores against the {} known poses (ADD < 0.15 diameter):\n{}", report.instances,
               evalReportTable(report.evaluation));
    printTimings(report.images);
    fmt::print("Total {:.1f} s: scenes {:.1f} s, banks {:.1f} s ({}), detection and scoring {:.1f} s\n", report.total_s,
               report.synth_s, report.train_s,
               std::all_of(report.objects.begin(), report.objects.end(), [](const auto& o) { return o.bank_from_cache; })
                   ? "cached"
                   : "trained",
               report.detect_s);
    fmt::print("Wrote {} (look at this), {}, {}\n", report.overlay_path, report.json_path, report.report_path);
    if (opt->pick) printPicks(report, params.out_dir);
    return 0;
  };
}

}  // namespace vkpose::cli
