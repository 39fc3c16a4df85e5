// `vkpose bench train`: training throughput, and OpenCV's training on the same renderings.
#include <filesystem>
#include <fstream>
#include <unistd.h>

#include <fmt/core.h>
#include <nlohmann/json.hpp>

#include "bench/bench_support.hpp"
#include "bench/train_benchmark.hpp"
#include "cli/commands.hpp"
#include "vkpose/error.hpp"

namespace vkpose::cli {

Runner addBenchTrainCommand(CLI::App& bench, const GlobalOptions& global) {
  auto* sub = bench.add_subcommand("train", "Training: templates per second, and cv::linemod on the same renderings");
  auto options = std::make_shared<bench::TrainBenchOptions>();
  auto json_path = std::make_shared<std::string>();
  sub->add_option("--mesh", options->mesh, "Mesh to train (default: ../shared/data/meshes/coffee_cup.stl)");
  sub->add_option("--views", options->viewpoints, "Viewpoints (x 5 radii x 13 in-plane rotations)")
      ->check(CLI::Range(1, 100000))
      ->capture_default_str();
  sub->add_option("--opencv-templates", options->opencv_templates, "Renderings OpenCV's training is timed on")
      ->check(CLI::Range(1, 100000))
      ->capture_default_str();
  sub->add_flag("!--no-reference", options->reference,
                "Skip the second training with the CPU reference quantization (the baseline of the ratio)");
  sub->add_option("--json", *json_path, "Write the result as JSON to this file (never overwritten)");
  return [options, json_path, &global]() {
    if (!json_path->empty() && std::filesystem::exists(*json_path))
      throw InputError("'" + *json_path + "' exists; vkpose does not overwrite results (remove it first)");
    options->progress = !global.quiet && isatty(STDERR_FILENO);
    const auto r = bench::runTrainBenchmark(*options, global.gpu());
    fmt::print("training: {}\n", r.mesh);
    fmt::print("device: {}\n", r.device);
    fmt::print("templates: {} in {:.1f} s ({:.0f} templates/s; render {:.1f} s, features {:.1f} s)\n", r.templates,
               r.total_s, r.templates_per_s, r.render_s, r.features_s);
    if (options->reference)
      fmt::print("same training, views quantized by the CPU reference: {:.1f} s (features {:.1f} s); GPU quantization "
                 "is {:.2f}x faster over the whole training{}\n",
                 r.reference_total_s, r.reference_features_s, r.reference_total_s / r.total_s,
                 r.reference_identical ? ", identical templates" : "; TEMPLATES DIFFER (a parity bug)");
    fmt::print("per template on the same {} renderings, one core: vkpose features (CPU reference) {:.2f} ms, "
               "cv::linemod addTemplate {:.2f} ms "
               "({} refused for < 63 features)\n",
               r.opencv_templates, r.vkpose_features_ms, r.opencv_ms, r.opencv_refused);
    fmt::print("ratio (cv::linemod ms per template / vkpose ms per template, whole training): {:.2f}\n", r.ratio);
    bench::printKernelProfile();
    if (!json_path->empty()) {
      nlohmann::json j = {{"mesh", r.mesh},
                                {"device", r.device},
                                {"templates", r.templates},
                                {"total_s", r.total_s},
                                {"render_s", r.render_s},
                                {"features_s", r.features_s},
                                {"templates_per_s", r.templates_per_s},
                                {"vkpose_features_ms", r.vkpose_features_ms},
                                {"opencv_ms_per_template", r.opencv_ms},
                                {"opencv_refused", r.opencv_refused},
                                {"ratio", r.ratio}};
      if (options->reference) {
        j["reference_total_s"] = r.reference_total_s;
        j["reference_features_s"] = r.reference_features_s;
        j["reference_identical"] = r.reference_identical;
      }
      std::ofstream(*json_path) << j.dump(2) << "\n";
    }
    return kOk;
  };
}

}  // namespace vkpose::cli
