// `vkpose demo` (demo.hpp): procedural objects piled in a bin, trained, detected and scored.
#include "vkpose/synth.hpp"

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <optional>

#include <fmt/format.h>

#include "eval/baselines.hpp"
#include "match/matcher.hpp"
#include "render/render.hpp"
#include "util/timing.hpp"
#include "vkpose/bank.hpp"
#include "vkpose/detector.hpp"
#include "vkpose/device.hpp"
#include "vkpose/error.hpp"
#include "vkpose/evaluation.hpp"
#include "vkpose/geometry.hpp"
#include "vkpose/picking.hpp"

namespace vkpose {

namespace fs = std::filesystem;
using util::msSince;

namespace {

/// Written into out_dir so that a later demo knows the folder is its own to replace.
constexpr const char* kMarker = ".vkpose-demo";
/// Everything the demo writes under out_dir; nothing else there is touched.
const std::vector<std::string> kOutputs = {"meshes",      "dataset",        "overlays",    "detections",
                                           "overlay.png", "detections.json", "report.json", "results_vkpose.csv"};

void prepareOutDir(const DemoParams& params) {
  const fs::path out(params.out_dir);
  std::error_code ec;
  if (fs::exists(out, ec)) {
    if (!fs::is_directory(out, ec)) throw InputError(fmt::format("{} exists and is not a folder", params.out_dir));
    const bool ours = fs::exists(out / kMarker, ec);
    if (!ours && !params.overwrite && !fs::is_empty(out, ec))
      throw InputError(fmt::format("{} exists and was not written by vkpose demo: choose another --out, or pass "
                                   "--force to replace what the demo writes there",
                                   params.out_dir));
    for (const auto& name : kOutputs) fs::remove_all(out / name, ec);
  }
  fs::create_directories(out, ec);
  if (ec) throw InputError(fmt::format("cannot create {}: {}", params.out_dir, ec.message()));
  writeTextFile((out / kMarker).string(), "written by vkpose demo; a later demo may replace this folder's outputs\n",
                true);
}

SynthParams binScenes(const DemoParams& params, const std::vector<std::string>& mesh_paths) {
  SynthParams s;
  s.meshes = mesh_paths;
  s.units = MeshUnits::Millimetres;
  s.images = params.images;
  s.seed = params.seed;
  s.min_instances = params.min_instances;
  s.max_instances = params.max_instances;
  s.clutter = 0;
  s.placement.layout = Layout::Bin;
  s.placement.upright_only = true;
  s.placement.bin_max_tilt_deg = 6.f;
  s.placement.bin_inner_m = {0.46f, 0.36f};
  s.fit_bin_to_parts = false;  // the demo's own bin
  CameraRange camera;
  camera.min_height_m = 0.75f;
  camera.max_height_m = 0.85f;
  camera.max_tilt_deg = 12.f;
  camera.target_jitter_m = 0.03f;
  s.camera_range = camera;
  return s;
}

}  // namespace

void validateDemoParams(const DemoParams& params) {
  if (params.out_dir.empty()) throw InputError("the demo needs an output folder (--out)");
  if (params.images < 1 || params.images > 100)
    throw InputError(fmt::format("the demo renders 1 to 100 scenes, not {}", params.images));
  if (params.min_instances < 1 || params.max_instances < params.min_instances || params.max_instances > 5)
    throw InputError(fmt::format("instances per object must satisfy 1 <= min <= max <= 5, not {}:{}",
                                 params.min_instances, params.max_instances));
  validateViewSampling(params.views);
  if (!(params.max_view_angle_deg > 0.f && params.max_view_angle_deg <= 90.f))
    throw InputError(fmt::format("the view angle must be in (0, 90] degrees, not {}", params.max_view_angle_deg));
  validateDetectorParams(params.detector);
}

namespace {
std::vector<std::string> writeMeshes(const std::vector<Mesh>& meshes, const std::string& dir, bool overwrite) {
  fs::create_directories(dir);
  std::vector<std::string> paths;
  for (const Mesh& mesh : meshes) {
    paths.push_back((fs::path(dir) / (mesh.name + ".ply")).string());
    writePlyMillimetres(mesh, paths.back(), overwrite);
  }
  return paths;
}
}  // namespace

std::vector<std::string> writeDemoMeshes(const std::string& dir, bool overwrite) {
  return writeMeshes(demoMeshes(), dir, overwrite);
}

std::vector<std::string> writePartMeshes(const std::string& dir, bool overwrite) {
  return writeMeshes(partMeshes(), dir, overwrite);
}

namespace {

/// Step 3 of the demo: a bank per object, read from the cache when one was trained with the
/// same mesh, camera and views before; each object's line in the report.
std::map<int, TemplateBank> demoBanks(GpuContext& ctx, const DemoParams& params, const std::vector<std::string>& mesh_paths,
                                      const Camera& camera, const DemoCallbacks& callbacks, DemoReport& report) {
  std::map<int, TemplateBank> banks;
  for (std::size_t i = 0; i < mesh_paths.size(); ++i) {
    DemoObject obj;
    obj.obj_id = static_cast<int>(i) + 1;
    obj.mesh_path = mesh_paths[i];
    const Mesh mesh = loadMesh(mesh_paths[i], MeshUnits::Millimetres);
    obj.name = mesh.name;
    TrainingParams tp;
    tp.views = params.views;
    tp.camera = camera;
    const std::vector<TrainingView> views =
        viewsAbove(sampleViews(tp.views, mesh.bboxCentre()), mesh.bboxCentre(), params.max_view_angle_deg);
    if (callbacks.step) callbacks.step(fmt::format("Template bank of {} ({} views)", obj.name, views.size()));
    const auto t_obj = std::chrono::steady_clock::now();
    CachedBank cached = loadOrTrainBank(ctx, mesh, tp, views, params.cache_dir, callbacks.progress);
    obj.train_s = msSince(t_obj) / 1e3;
    obj.bank_path = cached.path;
    obj.bank_from_cache = cached.from_cache;
    obj.templates = cached.bank.templates.size();
    if (callbacks.info) callbacks.info(fmt::format("{} templates, {} in {:.1f} s{}", obj.templates, cached.from_cache ? "read from the cache" : "trained",
                     obj.train_s, cached.path.empty() ? "" : " (" + cached.path + ")"));
    banks.emplace(obj.obj_id, std::move(cached.bank));
    report.objects.push_back(std::move(obj));
  }
  return banks;
}

}  // namespace

DemoReport runDemo(GpuContext& ctx, const DemoParams& params, const DemoCallbacks& callbacks) {
  validateDemoParams(params);
  const auto t_start = std::chrono::steady_clock::now();
  auto step = [&](const std::string& what) {
    if (callbacks.step) callbacks.step(what);
  };
  auto info = [&](const std::string& line) {
    if (callbacks.info) callbacks.info(line);
  };
  DemoReport report;
  report.device = ctx.device().name;
  prepareOutDir(params);
  const fs::path out(params.out_dir);

  // 1. The objects, built in code and written as PLY (millimetres) for the user to look at.
  const std::vector<std::string> mesh_paths = writeDemoMeshes((out / "meshes").string(), true);

  // 2. The bin scenes, in BOP format.
  step(fmt::format("Rendering {} bin scene{} with sensor noise", params.images, params.images == 1 ? "" : "s"));
  auto t = std::chrono::steady_clock::now();
  const std::string dataset_dir = (out / "dataset").string();
  const SynthParams synth = binScenes(params, mesh_paths);
  const SynthSummary made = generateSyntheticDataset(ctx, synth, dataset_dir, true, [&](int done, int total) {
    if (callbacks.progress) callbacks.progress(static_cast<std::size_t>(done), static_cast<std::size_t>(total));
  });
  report.synth_s = msSince(t) / 1e3;
  report.instances = made.instances;
  info(fmt::format("{} instances of {} objects, {:.1f} s per scene", made.instances, mesh_paths.size(),
                   made.ms_per_image / 1e3));
  const BopDataset dataset = loadBopDataset(dataset_dir);

  // 3. A bank per object, read from the cache when one was trained with the same mesh,
  //    camera and views before.
  t = std::chrono::steady_clock::now();
  std::map<int, TemplateBank> banks = demoBanks(ctx, params, mesh_paths, synth.camera, callbacks, report);
  report.train_s = msSince(t) / 1e3;

  // 4. Detection and scoring; each image's overlay and JSON as it comes.
  step(fmt::format("Detecting and scoring {} scene{}", dataset.images.size(), dataset.images.size() == 1 ? "" : "s"));
  t = std::chrono::steady_clock::now();
  std::vector<TemplateBank> bank_list;
  for (const auto& [obj_id, bank] : banks) bank_list.push_back(bank);
  fs::create_directories(out / "overlays");
  fs::create_directories(out / "detections");
  EvalRunParams run;
  run.methods = {EvalMethod::Vkpose};
  run.detector = params.detector;
  run.on_detections = [&](const BopImage& im, const LinemodFrame& frame, const DetectionResult& result) {
    DemoImageResult r;
    r.image_id = im.image_id;
    r.overlay_path = (out / "overlays" / fmt::format("{:06d}.png", im.image_id)).string();
    r.json_path = (out / "detections" / fmt::format("{:06d}.json", im.image_id)).string();
    writeImage(r.overlay_path, drawDetections(frame.bgr, result, bank_list, im.camera), true);
    writeTextFile(r.json_path, detectionJson(result, {im.rgb_path, im.depth_path, report.device}), true);
    r.result = result;
    report.images.push_back(std::move(r));
  };
  report.evaluation = runEvaluation(ctx, dataset, banks, run, callbacks.progress);
  report.detect_s = msSince(t) / 1e3;

  // 5. The scores, and the first image's outputs where a person looks first.
  report.report_path = (out / "report.json").string();
  writeTextFile(report.report_path, evalReportJson(report.evaluation), true);
  saveBopResults((out / "results_vkpose.csv").string(), report.evaluation.methods.front().results);
  if (!report.images.empty()) {
    report.overlay_path = (out / "overlay.png").string();
    report.json_path = (out / "detections.json").string();
    fs::copy_file(report.images.front().overlay_path, report.overlay_path, fs::copy_options::overwrite_existing);
    fs::copy_file(report.images.front().json_path, report.json_path, fs::copy_options::overwrite_existing);
  }
  report.total_s = msSince(t_start) / 1e3;
  for (auto& [obj_id, bank] : banks) report.banks.push_back(std::move(bank));
  return report;
}

std::vector<PickPlan> planDemoPicks(const DemoReport& report, const std::string& out_dir) {
  const fs::path out(out_dir);
  std::vector<std::vector<Grasp>> grasps;
  for (const TemplateBank& bank : report.banks) grasps.push_back(expandBySymmetry(faceSuctionGrasps(bank.mesh), bank));
  const BopDataset dataset = loadBopDataset((out / "dataset").string());
  std::vector<PickPlan> plans;
  for (const DemoImageResult& image : report.images) {
    const auto it = std::find_if(dataset.images.begin(), dataset.images.end(),
                                 [&](const BopImage& im) { return im.image_id == image.image_id; });
    if (it == dataset.images.end()) throw InputError(fmt::format("{}: no scene image {}", out_dir, image.image_id));
    const LinemodFrame frame = loadFrame(it->rgb_path, it->depth_path, it->camera.depth_scale);
    cv::Mat depth_m;
    frame.depth_mm.convertTo(depth_m, CV_32F, 0.001);
    Camera camera = it->camera;
    camera.width = frame.depth_mm.cols, camera.height = frame.depth_mm.rows;
    const std::optional<BinBox> bin = loadSynthBin(*it);
    PickPlan plan = planPicks(image.result.detections, report.banks, grasps, depth_m, camera, bin, PickParams{});
    cv::Mat overlay = drawDetections(frame.bgr, image.result, report.banks, camera);
    drawPicks(overlay, plan, camera);
    const std::string stem = fs::path(image.overlay_path).replace_extension().string();
    writeImage(stem + "_picks.png", overlay, true);
    writeTextFile(stem + "_picks.json", pickPlanJson(plan), true);
    plans.push_back(std::move(plan));
  }
  return plans;
}

}  // namespace vkpose
