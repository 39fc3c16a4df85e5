// `vkpose detect --bank BANK ... --rgb RGB --depth DEPTH --camera camera.json`: stages 1-8 on
// one frame, for several objects at once; prints the detections and the time of each stage,
// and writes the detection JSON and an overlay PNG. With --frames DIR or --list FILE instead of
// --rgb/--depth, a sequence of frames in one process: the banks are loaded and the detector is
// set up once, and each frame's JSON (and overlay) goes to --out-dir, or all frames' JSON to
// one JSON Lines file (--jsonl).
#include <algorithm>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <map>
#include <optional>
#include <sstream>

#include <fmt/core.h>
#include <nlohmann/json.hpp>

#include "bench/bench_support.hpp"
#include "cli/commands.hpp"
#include "util/progress.hpp"
#include "vkpose/detector.hpp"
#include "vkpose/error.hpp"
#include "vkpose/evaluation.hpp"
#include "vkpose/frame.hpp"
#include "vkpose/picking.hpp"

namespace vkpose::cli {

using util::ProgressBar;

namespace {

/// The lengths of stages 7-8 each object gets (config.hpp's scaled lengths), at the middle of
/// its bank's training distances, where its pose candidates mostly lie.
void printScaledLengths(const std::vector<TemplateBank>& banks, const DetectorParams& params) {
  for (const auto& b : banks) {
    const float z = 0.5f * (b.params.views.radii.from + b.params.views.radii.to);
    fmt::print("lengths for {} ({:.0f} mm across, at {:.2f} m, depth noise {:.1f} mm): {}\n", b.object, 1e3f * b.diameter,
               z, 1e3f * depthNoise(params.sensor, z), scaledLengthsReport(params, b.diameter, z));
  }
}

struct DetectOptions {
  std::vector<std::string> banks;
  std::string rgb, depth, camera, camera_entry, out, overlay, config, sensor;
  std::string frames, list, out_dir, jsonl;  // sequences
  bool overlays = false;
  OverlayOptions overlay_options;
  bool side_by_side = false;
  double depth_scale = 0;  // 0: the camera file's
  bool force = false;
  DetectorParams params;
  // Bin picking
  std::vector<std::string> grasps;
  std::string bin, pick_order = "combined";
  PickParams pick;
  std::vector<float> approach_axis;
};

/// The pick list of one frame's detections, printed.
PickPlan planFramePicks(const DetectOptions& opt, const std::vector<std::vector<Grasp>>& grasps,
                        const std::optional<BinBox>& bin, const std::vector<TemplateBank>& banks,
                        const DetectionResult& result, const LinemodFrame& frame, const Camera& camera, bool quiet) {
  cv::Mat depth_m;
  frame.depth_mm.convertTo(depth_m, CV_32F, 0.001);
  const PickPlan plan = planPicks(result.detections, banks, grasps, depth_m, camera, bin, opt.pick);
  if (quiet) return plan;
  fmt::print("pick list ({}): {} of {} detections with a grasp that hits nothing\n", opt.pick_order, plan.picks.size(),
             result.detections.size());
  for (std::size_t k = 0; k < plan.picks.size(); ++k) {
    const Pick& p = plan.picks[k];
    fmt::print("  {:>2}. detection {} ({}), grasp '{}', tilt {:.0f} deg, rank {:.2f} (score {:.2f}, visible {:.2f}, "
               "height {:.2f}, reach {:.2f}, free {:.2f})\n",
               k + 1, p.detection + 1, result.detections[static_cast<std::size_t>(p.detection)].object, p.grasp.name,
               p.grasp.tilt_deg, p.rank, p.score, p.visible, p.height, p.reach, p.free);
  }
  for (std::size_t i = 0; i < plan.detections.size(); ++i)
    for (const RefusedGrasp& r : plan.detections[i].refused)
      fmt::print("  detection {}: grasp '{}' refused: {}\n", i + 1, r.name, r.reason);
  return plan;
}

/// The detection JSON with each detection's grasps and the pick list in it.
std::string withPicks(const std::string& detection_json, const PickPlan& plan) {
  nlohmann::json doc = nlohmann::json::parse(detection_json);
  const nlohmann::json picks = nlohmann::json::parse(pickPlanJson(plan));
  for (std::size_t i = 0; i < doc["detections"].size() && i < picks["grasps"].size(); ++i)
    doc["detections"][i]["grasps"] = picks["grasps"][i];
  doc["picks"] = picks["picks"];
  return doc.dump(2) + "\n";
}

/// One frame of a sequence: its images, the name its outputs take, and its camera.
struct SequenceFrame {
  std::string rgb, depth, name;
  Camera camera;
};

namespace fs = std::filesystem;

/// The frames of DIR/rgb and DIR/depth (a BOP scene folder: the same file stem in both; the
/// colour may be .png or .jpg). Cameras: `camera_path` when given, else DIR/scene_camera.json's
/// entry of each frame's number.
std::vector<SequenceFrame> framesOfFolder(const std::string& dir, const std::string& camera_path,
                                          const std::string& camera_entry, double depth_scale) {
  const fs::path rgb_dir = fs::path(dir) / "rgb", depth_dir = fs::path(dir) / "depth";
  if (!fs::is_directory(rgb_dir) || !fs::is_directory(depth_dir))
    throw InputError(fmt::format("{}: expected the folders rgb/ and depth/ in it (a BOP scene folder)", dir));
  std::map<int, Camera> scene_cameras;
  Camera fixed;
  const bool per_frame = camera_path.empty();
  if (per_frame) {
    const fs::path scene_camera = fs::path(dir) / "scene_camera.json";
    if (!fs::exists(scene_camera))
      throw InputError(fmt::format("{}: no scene_camera.json in it; pass --camera FILE", dir));
    scene_cameras = loadSceneCamera(scene_camera.string());
  } else {
    fixed = loadCamera(camera_path, camera_entry);
  }
  std::vector<SequenceFrame> frames;
  std::vector<fs::path> colour;
  for (const auto& entry : fs::directory_iterator(rgb_dir)) {
    const std::string ext = entry.path().extension().string();
    if (entry.is_regular_file() && (ext == ".png" || ext == ".jpg" || ext == ".jpeg")) colour.push_back(entry.path());
  }
  std::sort(colour.begin(), colour.end());
  for (const fs::path& rgb : colour) {
    SequenceFrame f;
    f.rgb = rgb.string();
    f.depth = (depth_dir / (rgb.stem().string() + ".png")).string();
    f.name = rgb.stem().string();
    if (per_frame) {
      int id = -1;
      try {
        id = std::stoi(f.name);
      } catch (const std::exception&) {
      }
      const auto it = scene_cameras.find(id);
      if (it == scene_cameras.end())
        throw InputError(fmt::format("{}: scene_camera.json has no entry for frame {}", dir, f.name));
      f.camera = it->second;
    } else {
      f.camera = fixed;
    }
    if (depth_scale > 0) f.camera.depth_scale = depth_scale;
    frames.push_back(f);
  }
  if (frames.empty()) throw InputError(fmt::format("{}: no colour images (.png, .jpg) in rgb/", dir));
  return frames;
}

/// The frames of a list file: one "RGB DEPTH" pair a line (paths relative to the list's
/// folder unless absolute; blank lines and lines starting with # are skipped), all seen by
/// the camera of `camera_path`.
std::vector<SequenceFrame> framesOfList(const std::string& list, const std::string& camera_path,
                                        const std::string& camera_entry, double depth_scale) {
  std::ifstream in(list);
  if (!in) throw InputError(fmt::format("{}: cannot open the frame list", list));
  Camera camera = loadCamera(camera_path, camera_entry);
  if (depth_scale > 0) camera.depth_scale = depth_scale;
  const fs::path base = fs::path(list).parent_path();
  std::vector<SequenceFrame> frames;
  std::map<std::string, int> names;
  std::string line;
  for (int number = 1; std::getline(in, line); ++number) {
    const auto first = line.find_first_not_of(" \t\r");
    if (first == std::string::npos || line[first] == '#') continue;
    std::istringstream fields(line);
    std::string rgb, depth, extra;
    if (!(fields >> rgb >> depth) || (fields >> extra))
      throw InputError(fmt::format("{}:{}: expected two paths, the colour image and the depth image", list, number));
    auto resolve = [&](const std::string& p) { return fs::path(p).is_absolute() ? p : (base / p).string(); };
    SequenceFrame f{resolve(rgb), resolve(depth), fs::path(rgb).stem().string(), camera};
    // Two frames with the same file name (from different folders) get distinct output names.
    if (const int seen = names[f.name]++; seen > 0) f.name += fmt::format("_{}", seen + 1);
    frames.push_back(f);
  }
  if (frames.empty()) throw InputError(fmt::format("{}: lists no frames", list));
  return frames;
}

/// A file the sequence is about to write: InputError when it exists and --force was not given.
void checkWritable(const std::string& path, bool force) {
  if (!force && fs::exists(path)) throw InputError(path + " exists: pass --force to overwrite it");
}

std::vector<TemplateBank> loadBanks(const std::vector<std::string>& paths, bool quiet) {
  std::vector<TemplateBank> banks;
  ProgressBar bar("loading banks", quiet);
  for (std::size_t i = 0; i < paths.size(); ++i) {
    banks.push_back(loadBank(paths[i]));
    bar.update(i + 1, paths.size());
  }
  return banks;
}

/// Image size of a frame's overlay camera: scene_camera.json entries carry none.
Camera withFrameSize(Camera camera, const LinemodFrame& frame) {
  camera.width = frame.bgr.cols;
  camera.height = frame.bgr.rows;
  return camera;
}

/// --frames / --list: every frame through one detector. A frame that cannot be used (a missing
/// or corrupt image, another size) is reported and skipped; the command then exits 1.
ExitCode runSequence(const DetectOptions& opt, const DetectorParams& params, const GlobalOptions& global) {
  if (opt.out_dir.empty() && opt.jsonl.empty())
    throw InputError("a frame sequence needs --out-dir DIR or --jsonl FILE for its results");
  const std::vector<SequenceFrame> frames =
      !opt.frames.empty() ? framesOfFolder(opt.frames, opt.camera, opt.camera_entry, opt.depth_scale)
                          : framesOfList(opt.list, opt.camera, opt.camera_entry, opt.depth_scale);
  // Every output is checked before any work, so a run never stops half-way for a file that exists.
  auto outPath = [&](const SequenceFrame& f, const char* ext) { return (fs::path(opt.out_dir) / (f.name + ext)).string(); };
  if (!opt.out_dir.empty()) {
    fs::create_directories(opt.out_dir);
    for (const SequenceFrame& f : frames) {
      checkWritable(outPath(f, ".json"), opt.force);
      if (opt.overlays) checkWritable(outPath(f, ".png"), opt.force);
    }
  }
  std::ofstream jsonl;
  if (!opt.jsonl.empty()) {
    checkWritable(opt.jsonl, opt.force);
    jsonl.open(opt.jsonl, std::ios::trunc);
    if (!jsonl) throw InputError(opt.jsonl + ": cannot be written");
  }

  GpuContext ctx(global.gpu());
  Detector detector(ctx, loadBanks(opt.banks, global.quiet), params);
  if (global.verbose && params.estimate_poses) printScaledLengths(detector.banks(), params);
  if (!global.quiet)
    fmt::print("{} frame{}, {} object{} on {}\n", frames.size(), frames.size() == 1 ? "" : "s", opt.banks.size(),
               opt.banks.size() == 1 ? "" : "s", ctx.device().name);
  ProgressBar bar("detecting", global.quiet);
  std::size_t detections = 0, failed = 0;
  std::vector<double> frame_ms;
  for (std::size_t i = 0; i < frames.size(); ++i) {
    const SequenceFrame& f = frames[i];
    try {
      const LinemodFrame frame = loadFrame(f.rgb, f.depth, f.camera.depth_scale);
      const auto t0 = std::chrono::steady_clock::now();
      const DetectionResult result = detector.detect(frame, f.camera);
      frame_ms.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
      detections += result.detections.size();
      const std::string json = detectionJson(result, {f.rgb, f.depth, ctx.device().name});
      if (!opt.out_dir.empty()) writeTextFile(outPath(f, ".json"), json, true);
      if (jsonl.is_open()) jsonl << nlohmann::json::parse(json).dump() << '\n';
      if (opt.overlays)
        writeImage(outPath(f, ".png"),
                   drawDetections(frame.bgr, result, detector.banks(), withFrameSize(f.camera, frame),
                                  opt.overlay_options),
                   true);
      if (global.verbose) {
        bar.finish();
        fmt::print("{}: {} detection{}, {:.0f} ms\n", f.name, result.detections.size(),
                   result.detections.size() == 1 ? "" : "s", frame_ms.back());
      }
    } catch (const InputError& e) {
      ++failed;
      bar.finish();
      fmt::print(stderr, "vkpose: frame {}: {}\n", f.name, e.what());
      if (jsonl.is_open()) jsonl << nlohmann::json{{"rgb", f.rgb}, {"depth", f.depth}, {"error", e.what()}}.dump() << '\n';
    }
    bar.update(i + 1, frames.size());
  }
  bar.finish();
  if (!jsonl) throw InputError(opt.jsonl + ": writing failed");
  const double median = frame_ms.empty() ? 0 : bench::median(frame_ms);
  fmt::print("{} of {} frames, {} detection{}, median {:.0f} ms a frame ({:.2f} frames/s); results in {}\n",
             frames.size() - failed, frames.size(), detections, detections == 1 ? "" : "s", median,
             median > 0 ? 1000.0 / median : 0.0, opt.out_dir.empty() ? opt.jsonl : opt.out_dir);
  return failed > 0 ? kBadInput : kOk;
}

/// `vkpose detect` of one frame (or, with --frames or --list, a sequence: runSequence).
ExitCode runDetect(const DetectOptions& opt, const GlobalOptions& global) {
  DetectorParams params = withConfig(opt.config, opt.params);
  if (!opt.sensor.empty()) params.sensor = sensorProfile(opt.sensor);
  if (!opt.frames.empty() || !opt.list.empty()) return runSequence(opt, params, global);
  for (const std::string* path : {&opt.out, &opt.overlay})
    if (!path->empty()) checkWritable(*path, opt.force);
  if (!opt.grasps.empty() && opt.depth.empty())
    throw InputError("--grasps needs a depth image (--depth): grasps are checked against the scene's points");
  Camera camera = loadCamera(opt.camera, opt.camera_entry);
  if (opt.depth_scale > 0) camera.depth_scale = opt.depth_scale;
  const LinemodFrame frame = loadFrame(opt.rgb, opt.depth, camera.depth_scale);

  std::vector<TemplateBank> banks = loadBanks(opt.banks, global.quiet);
  // Grasps and the bin are read and checked before any work.
  const std::vector<std::vector<Grasp>> grasps = graspsForBanks(opt.grasps, banks, opt.pick.symmetry_steps);
  std::optional<BinBox> bin;
  if (!opt.bin.empty()) bin = loadBin(opt.bin);
  if (!opt.grasps.empty() && !params.estimate_poses) throw InputError("--grasps needs the pose stages (not --no-pose)");
  GpuContext ctx(global.gpu());
  Detector detector(ctx, std::move(banks), params);
  const DetectionResult result = detector.detect(frame, camera);
  for (const auto& w : result.warnings) fmt::print(stderr, "vkpose: warning: {}\n", w);

  if (frame.depth_mm.empty())
    fmt::print("{} detection{} colour only ({} matches, {} hypotheses) on {}\n", result.detections.size(),
               result.detections.size() == 1 ? "" : "s", result.matches, result.hypotheses, ctx.device().name);
  else
    fmt::print("{} detection{} ({} matches, {} hypotheses, {} scored above {:.2f}) on {}\n", result.detections.size(),
               result.detections.size() == 1 ? "" : "s", result.matches, result.hypotheses,
               result.scored_hypotheses, params.estimate_poses ? params.pose_min_score : params.min_score,
               ctx.device().name);
  if (global.verbose && result.match_pairs > 0)
    fmt::print("depth-guided pruning: {:.1f} % of {} (template, position) pairs pruned, {:.1f} % skipped unread\n",
               100.0 * static_cast<double>(result.match_pairs_pruned) / static_cast<double>(result.match_pairs),
               result.match_pairs,
               100.0 * static_cast<double>(result.match_pairs_skipped) / static_cast<double>(result.match_pairs));
  if (global.verbose && params.estimate_poses) printScaledLengths(detector.banks(), params);
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
  std::optional<PickPlan> plan;
  if (!opt.grasps.empty())
    plan = planFramePicks(opt, grasps, bin, detector.banks(), result, frame, withFrameSize(camera, frame), global.quiet);
  if (!opt.out.empty()) {
    const std::string json = detectionJson(result, {opt.rgb, opt.depth, ctx.device().name});
    writeTextFile(opt.out, plan ? withPicks(json, *plan) : json, opt.force);
    if (!global.quiet) fmt::print("wrote {}\n", opt.out);
  }
  if (!opt.overlay.empty()) {
    OverlayOptions overlay = opt.overlay_options;
    if (opt.side_by_side) overlay.depth_mm = frame.depth_mm;
    cv::Mat image = drawDetections(frame.bgr, result, detector.banks(), withFrameSize(camera, frame), overlay);
    if (plan) drawPicks(image, *plan, withFrameSize(camera, frame));
    writeImage(opt.overlay, image, opt.force);
    if (!global.quiet) fmt::print("wrote {}\n", opt.overlay);
  }
  return kOk;
}

/// The stage parameters `detect` takes as flags (a --config file sets every one).
}  // namespace

void addPickFlags(CLI::App* sub, CLI::Option* grasps, std::string& pick_order, PickParams& pick,
                  const std::string& group) {
  sub->add_option("--pick-order", pick_order, "What the pick list is ordered by: combined, height, score, visible")
      ->check(CLI::IsMember({"combined", "height", "score", "visible"}))
      ->capture_default_str()
      ->needs(grasps)
      ->group(group);
  sub->add_option("--max-tilt", pick.max_tilt_deg,
                  "Grasps whose approach is tilted further than this from the approach axis are refused, degrees")
      ->check(CLI::Range(1.0, 180.0))
      ->capture_default_str()
      ->needs(grasps)
      ->group(group);
  sub->add_option("--min-outline-fit", pick.min_outline_on_edges,
                  "A detection is picked only when this share of its outline lies on the image's edges (its "
                  "outline_on_edges; 0: off)")
      ->check(CLI::Range(0.0, 1.0))
      ->capture_default_str()
      ->needs(grasps)
      ->group(group);
  sub->add_option("--min-colour-fit", pick.min_colour_agreement,
                  "A detection is picked only when its colour agrees with its model's at least this much (its "
                  "colour_agreement, measured where the mesh has colours; 0: off)")
      ->check(CLI::Range(0.0, 1.0))
      ->capture_default_str()
      ->needs(grasps)
      ->group(group);
  sub->add_option("--colour-outline-allowance", pick.colour_outline_allowance,
                  fmt::format("--min-outline-fit asks up to this much less of a detection whose colour was measured and "
                              "passed --min-colour-fit: all of it at a colour agreement of 1, none at {:g}, linear between",
                              kColourOutlineAllowanceFrom))
      ->check(CLI::Range(0.0, 1.0))
      ->capture_default_str()
      ->needs(grasps)
      ->group(group);
}

Runner addDetectCommand(CLI::App& app, const GlobalOptions& global) {
  auto opt = std::make_shared<DetectOptions>();
  auto& p = opt->params;
  auto* sub = app.add_subcommand("detect", "Find the objects of one or more template banks in an RGB-D frame");
  sub->add_option("--bank", opt->banks, "Template bank (.vkpb) of an object; repeat for several objects")
      ->required();  // a missing bank is bad input (exit 1, loadBank names it), not a usage error
  // The input: one frame (--rgb with --depth) or a sequence (--frames or --list), exactly one.
  auto* input = sub->add_option_group("Input", "One frame (--rgb and --depth) or a sequence (--frames or --list)");
  auto* rgb = input->add_option("--rgb", opt->rgb, "Colour image (PNG/JPEG, 8-bit)");
  auto* frames = input->add_option("--frames", opt->frames,
                                   "Folder of a frame sequence: rgb/ and depth/ with the same file names (a BOP scene "
                                   "folder; cameras from its scene_camera.json unless --camera is given)");
  auto* list = input->add_option("--list", opt->list,
                                 "Text file of a frame sequence: a colour and a depth image path per line");
  input->require_option(1);
  auto* depth = sub->add_option("--depth", opt->depth,
                                "Depth image (16-bit PNG, aligned to the colour image); without it, colour-only detection "
                                "(the banks' colour templates, poses fitted to the image's edges)");
  depth->needs(rgb);
  depth->excludes(frames)->excludes(list);
  auto* camera_opt = sub->add_option("--camera", opt->camera,
                                     "BOP camera.json (cam_K or fx/fy/cx/cy, depth_scale) or scene_camera.json (required "
                                     "but with --frames of a folder that has a scene_camera.json)");
  rgb->needs(camera_opt);
  list->needs(camera_opt);
  sub->add_option("--camera-entry", opt->camera_entry, "Key of the scene_camera.json entry (default: the first)");
  sub->add_option("--depth-scale", opt->depth_scale,
                  "Millimetres per depth-PNG unit (default: the camera file's depth_scale, else 1)")
      ->check(CLI::PositiveNumber);
  // One frame's outputs; a sequence writes to --out-dir or --jsonl.
  sub->add_option("--out", opt->out, "Detection JSON to write")->excludes(frames)->excludes(list);
  sub->add_option("--overlay", opt->overlay,
                  "Overlay PNG to write (model outlines and axes of the poses, labels, scores, legend)")
      ->excludes(frames)
      ->excludes(list);
  sub->add_flag("--show-rejected", opt->overlay_options.show_rejected,
                "Also draw the hypotheses that pose verification rejected (in red) on the overlay");
  sub->add_flag("--side-by-side", opt->side_by_side,
                "Put the depth image (false colour, with the same drawing) to the right of the colour overlay");
  auto* out_dir = sub->add_option(
      "--out-dir", opt->out_dir, "Sequences: folder for one detection JSON per frame (NAME.json, NAME the colour image's stem)");
  sub->add_option("--jsonl", opt->jsonl, "Sequences: one JSON Lines file, a frame's detection JSON per line");
  sub->add_flag("--overlays", opt->overlays, "Sequences: also write NAME.png overlays into --out-dir")->needs(out_dir);
  sub->add_flag("--force", opt->force, "Overwrite output files that exist");
  addConfigOption(sub, opt->config);
  addSensorOption(sub, opt->sensor,
                  "its noise sets the lengths that follow each object (vkpose config --explain); with close-range, "
                  "parts under 10 cm are also matched on colour alone (their depth is unreliable)");
  addStageFlags(sub, p, "Stage parameters");
  auto* picking = "Bin picking (docs/picking.md)";
  auto* grasps = sub->add_option("--grasps", opt->grasps,
                                 "Grasp file (JSON) of an object: its grasps are placed at each detection of it, "
                                 "checked, and the detections ordered into a pick list; repeat for several objects")
                     ->excludes(frames)
                     ->excludes(list)
                     ->group(picking);
  sub->add_option("--bin", opt->bin, "The bin (JSON: its pose in the camera frame, inner size, wall thickness)")
      ->needs(grasps)
      ->group(picking);
  addPickFlags(sub, grasps, opt->pick_order, opt->pick, picking);
  sub->add_option("--approach-axis", opt->approach_axis,
                  "The robot's approach direction in the camera frame, 3 numbers (default: down into the --bin, or 0 0 1 along "
                  "the camera's view without one)")
      ->expected(3)
      ->needs(grasps)
      ->group(picking);
  return [opt, &global]() {
    opt->pick.order = parsePickOrder(opt->pick_order);
    if (!opt->approach_axis.empty())
      opt->pick.approach_axis = Eigen::Vector3f(opt->approach_axis[0], opt->approach_axis[1], opt->approach_axis[2]);
    return runDetect(*opt, global);
  };
}

}  // namespace vkpose::cli
