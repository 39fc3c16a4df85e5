// `vkpose detect --bank BANK ... --rgb RGB --depth DEPTH --camera camera.json`: stages 1-5 on
// one frame, for several objects at once; prints the detections and the time of each stage,
// and writes the detection JSON and an overlay PNG.
#include <chrono>
#include <filesystem>

#include <fmt/core.h>

#include "cli/commands.hpp"
#include "util/progress.hpp"
#include "vkpose/detector.hpp"
#include "vkpose/error.hpp"
#include "vkpose/frame.hpp"

namespace vkpose::cli {

using util::ProgressBar;

namespace {
struct DetectOptions {
  std::vector<std::string> banks;
  std::string rgb, depth, camera, camera_entry, out, overlay, config;
  OverlayOptions overlay_options;
  bool side_by_side = false;
  double depth_scale = 0;  // 0: the camera file's
  bool force = false;
  DetectorParams params;
};
}  // namespace

Runner addDetectCommand(CLI::App& app, const GlobalOptions& global) {
  auto opt = std::make_shared<DetectOptions>();
  auto& p = opt->params;
  auto* sub = app.add_subcommand("detect", "Find the objects of one or more template banks in an RGB-D frame");
  sub->add_option("--bank", opt->banks, "Template bank (.vkpb) of an object; repeat for several objects")
      ->required();  // a missing bank is bad input (exit 1, loadBank names it), not a usage error
  sub->add_option("--rgb", opt->rgb, "Colour image (PNG/JPEG, 8-bit)")->required();
  sub->add_option("--depth", opt->depth, "Depth image (16-bit PNG, aligned to the colour image)")->required();
  sub->add_option("--camera", opt->camera, "BOP camera.json (cam_K or fx/fy/cx/cy, depth_scale) or scene_camera.json")
      ->required();
  sub->add_option("--camera-entry", opt->camera_entry, "Key of the scene_camera.json entry (default: the first)");
  sub->add_option("--depth-scale", opt->depth_scale,
                  "Millimetres per depth-PNG unit (default: the camera file's depth_scale, else 1)")
      ->check(CLI::PositiveNumber);
  sub->add_option("--out", opt->out, "Detection JSON to write");
  sub->add_option("--overlay", opt->overlay,
                  "Overlay PNG to write (model outlines and axes of the poses, labels, scores, legend)");
  sub->add_flag("--show-rejected", opt->overlay_options.show_rejected,
                "Also draw the hypotheses that pose verification rejected (in red) on the overlay");
  sub->add_flag("--side-by-side", opt->side_by_side,
                "Put the depth image (false colour, with the same drawing) to the right of the colour overlay");
  sub->add_flag("--force", opt->force, "Overwrite --out and --overlay if they exist");
  addConfigOption(sub, opt->config);
  auto* stages = "Stage parameters";
  sub->add_option("--threshold", p.match.threshold, "LINEMOD similarity a match needs, percent")
      ->check(CLI::Range(1.0, 100.0))
      ->capture_default_str()
      ->group(stages);
  sub->add_option("--cluster-step", p.cluster.position_step_px, "Clustering cell s_im, pixels")
      ->check(CLI::Range(1, 512))
      ->capture_default_str()
      ->group(stages);
  sub->add_option("--min-templates", p.cluster.min_templates, "Smallest cluster tau_c, templates")
      ->check(CLI::Range(1, 100000))
      ->capture_default_str()
      ->group(stages);
  sub->add_option("--pose-candidates", p.pose_candidates_per_object,
                  "Hypotheses per object that get a pose and verification (the best after NMS)")
      ->check(CLI::PositiveNumber)
      ->capture_default_str()
      ->group(stages);
  sub->add_option("--pose-min-score", p.pose_min_score, "Smallest cluster score gamma a hypothesis needs for a pose, 0..1")
      ->check(CLI::Range(0.0, 1.0))
      ->capture_default_str()
      ->group(stages);
  sub->add_option("--min-score", p.min_score, "With --no-pose: smallest cluster score gamma a detection needs, 0..1")
      ->check(CLI::Range(0.0, 1.0))
      ->capture_default_str()
      ->group(stages);
  sub->add_option("--depth-unit", p.score.depth_unit_m, "Cluster score: alpha = exp(-depth error / unit), metres")
      ->check(CLI::PositiveNumber)
      ->capture_default_str()
      ->group(stages);
  sub->add_option("--angle-unit", p.score.angle_unit_rad, "Cluster score: beta = exp(-normal angle / unit), radians")
      ->check(CLI::PositiveNumber)
      ->capture_default_str()
      ->group(stages);
  sub->add_option("--nms-radius", p.nms.radius_px,
                  "NMS radius r, pixels (0: half the projected object diameter)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str()
      ->group(stages);
  sub->add_flag("!--no-pose", p.estimate_poses,
                "Stop after NMS: report the best template's pose, without refinement or verification")
      ->group(stages);
  sub->add_option("--rotation-cluster", p.initial_pose.rotation_cluster_deg,
                  "Initial pose: template rotations closer than this vote together (tau_theta), degrees")
      ->check(CLI::Range(0.1, 180.0))
      ->capture_default_str()
      ->group(stages);
  sub->add_option("--icp-voxel", p.refine.voxel_size, "Refinement: voxel grid of scene and model, metres (0: none)")
      ->check(CLI::Range(0.0, 0.1))
      ->capture_default_str()
      ->group(stages);
  sub->add_option("--octree-resolution", p.verify.resolution, "Verification: octree leaf size, metres")
      ->check(CLI::Range(0.0005, 0.1))
      ->capture_default_str()
      ->group(stages);
  sub->add_option("--min-collision", p.verify.threshold,
                  "Verification: a pose is accepted when its collision rate phi exceeds this, 0..1")
      ->check(CLI::Range(0.0, 1.0))
      ->capture_default_str()
      ->group(stages);
  return [opt, &global]() {
    const DetectorParams params = withConfig(opt->config, opt->params);
    for (const auto* path : {&opt->out, &opt->overlay})
      if (!path->empty() && !opt->force && std::filesystem::exists(*path))
        throw InputError(*path + " exists: pass --force to overwrite it");
    Camera camera = loadCamera(opt->camera, opt->camera_entry);
    if (opt->depth_scale > 0) camera.depth_scale = opt->depth_scale;
    const LinemodFrame frame = loadFrame(opt->rgb, opt->depth, camera.depth_scale);

    std::vector<TemplateBank> banks;
    ProgressBar bar("loading banks", global.quiet);
    for (std::size_t i = 0; i < opt->banks.size(); ++i) {
      banks.push_back(loadBank(opt->banks[i]));
      bar.update(i + 1, opt->banks.size());
    }
    bar.finish();
    GpuContext ctx(global.gpu());
    Detector detector(ctx, std::move(banks), params);
    const DetectionResult result = detector.detect(frame, camera);
    for (const auto& w : result.warnings) fmt::print(stderr, "vkpose: warning: {}\n", w);

    fmt::print("{} detection{} ({} matches, {} hypotheses, {} scored above {:.2f}) on {}\n", result.detections.size(),
               result.detections.size() == 1 ? "" : "s", result.matches, result.hypotheses,
               result.scored_hypotheses,
               params.estimate_poses ? params.pose_min_score : params.min_score, ctx.device().name);
    if (!result.rejected.empty())
      fmt::print("{} hypothes{} rejected by pose verification{}\n", result.rejected.size(),
                 result.rejected.size() == 1 ? "is" : "es", global.verbose ? ":" : " (--verbose lists them)");
    auto table = [](const std::vector<Detection>& dets, bool reasons) {
      fmt::print("  {:>3}  {:<16} {:>6} {:>6} {:>6}  {:>20}  {:>24}  {}\n", "#", "object", "score", "gamma", "phi",
                 "box x,y,w,h (px)", "t (m)", reasons ? "why rejected" : "icp fitness (mm^2)");
      for (std::size_t i = 0; i < dets.size(); ++i) {
        const Detection& d = dets[i];
        fmt::print("  {:>3}  {:<16} {:>6.3f} {:>6.3f} {:>6}  {:>20}  {:>24}  {}\n", i + 1, d.object, d.score, d.gamma,
                   d.collision_rate >= 0.f ? fmt::format("{:.3f}", d.collision_rate) : "-",
                   fmt::format("{:.0f},{:.0f},{:.0f},{:.0f}", d.bbox.x, d.bbox.y, d.bbox.width, d.bbox.height),
                   fmt::format("{:.3f},{:.3f},{:.3f}", d.pose.t.x(), d.pose.t.y(), d.pose.t.z()),
                   reasons ? d.rejection : (d.collision_rate >= 0.f ? fmt::format("{:.2f}", d.icp_fitness * 1e6) : "-"));
      }
    };
    if (!result.detections.empty()) table(result.detections, false);
    if (global.verbose && !result.rejected.empty()) table(result.rejected, true);
    if (!global.quiet) {
      fmt::print("timings (ms):");
      for (const auto& [stage, ms] : result.timings_ms) fmt::print(" {} {:.1f}", stage, ms);
      fmt::print("\n");
    }
    if (!opt->out.empty()) {
      writeTextFile(opt->out, detectionJson(result, {opt->rgb, opt->depth, ctx.device().name}), opt->force);
      if (!global.quiet) fmt::print("wrote {}\n", opt->out);
    }
    if (!opt->overlay.empty()) {
      Camera image_camera = camera;  // scene_camera.json entries carry no size: the frame's
      image_camera.width = frame.bgr.cols;
      image_camera.height = frame.bgr.rows;
      OverlayOptions overlay = opt->overlay_options;
      if (opt->side_by_side) overlay.depth_mm = frame.depth_mm;
      writeImage(opt->overlay, drawDetections(frame.bgr, result, detector.banks(), image_camera, overlay), opt->force);
      if (!global.quiet) fmt::print("wrote {}\n", opt->overlay);
    }
    return kOk;
  };
}

}  // namespace vkpose::cli
