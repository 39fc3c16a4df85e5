#include "bench/detect_benchmark.hpp"

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <map>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "bench/bench_support.hpp"
#include "gpu/buffer.hpp"
#include "hypotheses/hypotheses.hpp"
#include "match/features.hpp"
#include "match/matcher.hpp"
#include "match/opencv_linemod.hpp"
#include "pipeline/colour_only.hpp"
#include "vkpose/bank.hpp"
#include "vkpose/device.hpp"
#include "vkpose/error.hpp"
#include "vkpose/frame.hpp"
#include "vkpose/geometry.hpp"
#include "vkpose/synth.hpp"

namespace vkpose::bench {

namespace {

namespace fs = std::filesystem;

struct BenchFrame {
  LinemodFrame frame;
  Camera camera;
};

/// "coffee_cup" and "CoffeeCup" name the same object.
std::string normalised(const std::string& s) {
  std::string out;
  for (const char c : s)
    if (std::isalnum(static_cast<unsigned char>(c))) out += static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return out;
}

bool lmoObjects(const std::vector<TemplateBank>& banks, const fs::path& lmo) {
  return std::all_of(banks.begin(), banks.end(), [&](const TemplateBank& b) {
    return b.object.rfind("obj_", 0) == 0 && fs::exists(lmo / "models" / (b.object + ".ply"));
  });
}

bool icbinObjects(const std::vector<TemplateBank>& banks) {
  return std::all_of(banks.begin(), banks.end(), [](const TemplateBank& b) {
    const std::string n = normalised(b.object);
    return n.find("cup") != std::string::npos || n.find("juice") != std::string::npos;
  });
}

std::vector<BenchFrame> lmoFrames(const fs::path& lmo, std::string& what) {
  const fs::path scene = lmo / "test" / "000002";
  if (!fs::exists(scene / "rgb" / "000003.png")) throw InputError("no LM-O frame under " + lmo.string());
  BenchFrame f;
  f.camera = loadCamera((lmo / "camera.json").string());
  f.frame = loadFrame((scene / "rgb" / "000003.png").string(), (scene / "depth" / "000003.png").string(),
                      f.camera.depth_scale);
  what = "LM-O test scene 2 image 3 (" + lmo.string() + ")";
  return {f};
}

/// The IC-BIN scenes that show the banks' objects: scene 1 juice cartons, 2 cups, 3 both.
std::vector<BenchFrame> icbinFrames(const fs::path& icbin, const std::vector<TemplateBank>& banks, std::string& what) {
  bool cup = false, juice = false;
  for (const auto& b : banks) {
    const std::string n = normalised(b.object);
    cup = cup || n.find("cup") != std::string::npos;
    juice = juice || n.find("juice") != std::string::npos;
  }
  std::vector<int> scenes;
  if (cup) scenes.push_back(2);
  if (juice) scenes.push_back(1);
  if (cup || juice || scenes.empty()) scenes.push_back(3);
  const Camera camera = loadCamera((icbin / "camera.json").string());
  std::vector<BenchFrame> frames;
  for (const int s : scenes)
    for (int i = 0; i < 3; ++i) {
      const fs::path dir = icbin / fmt::format("scene{}", s);
      const fs::path rgb = dir / "rgb" / fmt::format("{:04d}.png", i), depth = dir / "depth" / fmt::format("{:04d}.png", i);
      if (!fs::exists(rgb)) continue;
      frames.push_back({loadFrame(rgb.string(), depth.string(), camera.depth_scale), camera});
    }
  if (frames.empty()) throw InputError("no IC-BIN frames under " + icbin.string());
  std::string list;
  for (const int s : scenes) list += (list.empty() ? "" : ", ") + std::to_string(s);
  what = fmt::format("IC-BIN scenes {} ({} frames, {})", list, frames.size(), icbin.string());
  return frames;
}

/// Random table scenes of the banks' own meshes, 1-2 instances each, with clutter and sensor
/// noise, seen from the distances the banks were trained for, with their focal lengths.
std::vector<BenchFrame> syntheticFrames(const GpuContext& ctx, const std::vector<TemplateBank>& banks, int count,
                                        uint32_t seed, int instances, std::string& what) {
  SynthParams p;
  p.seed = seed;
  p.images = count;
  p.min_instances = instances > 0 ? instances : 1;
  p.max_instances = instances > 0 ? instances : 2;
  const Camera& trained = banks.front().params.camera;
  p.camera = Camera{trained.fx, trained.fy, 319.5, 239.5, 640, 480, 1.0};
  float near = banks.front().params.views.radii.from, far = banks.front().params.views.radii.to;
  for (const auto& b : banks) {
    near = std::min(near, b.params.views.radii.from);
    far = std::max(far, b.params.views.radii.to);
  }
  CameraRange camera;
  camera.min_height_m = near;
  camera.max_height_m = std::max(near, far);
  p.camera_range = camera;
  std::vector<Mesh> meshes;
  for (const auto& b : banks) {
    if (b.mesh.vertices.empty()) throw InputError("bank '" + b.object + "' carries no mesh: retrain it (bank version 2)");
    meshes.push_back(b.mesh);
  }
  std::vector<BenchFrame> frames;
  for (int i = 0; i < count; ++i) {
    SynthImage image = synthesizeImage(ctx, p, meshes, i);
    frames.push_back({std::move(image.frame), image.camera});
  }
  what = fmt::format("synthetic: {} random table scenes of the banks' meshes (seed {}, {} instances of each)", count,
                     seed, instances > 0 ? std::to_string(instances) : std::string("1-2"));
  return frames;
}

/// Stages 6-8 (a sweep's pose time).
bool isPoseStage(const std::string& name) {
  for (const Stage stage : {Stage::initial_pose, Stage::first_fit, Stage::mls, Stage::icp, Stage::verification,
                            Stage::symmetries})
    if (name == stageName(stage)) return true;
  return false;
}

/// The detector's stages as the report groups them (under the first's name): the match
/// readback goes with similarity; the template upload is reported apart.
const std::vector<std::vector<Stage>>& stageGroups() {
  static const std::vector<std::vector<Stage>> groups = {
      {Stage::features},
      {Stage::similarity, Stage::depth_pruning, Stage::match_readback},
      {Stage::clustering},
      {Stage::scoring},
      {Stage::nms},
      {Stage::initial_pose},
      {Stage::first_fit},
      {Stage::mls},
      {Stage::icp},
      {Stage::verification},
      {Stage::symmetries},
      {Stage::edges},        // colour only: the frame's edge maps
      {Stage::contour_fit},  // colour only: stage 7 on the image's edges
  };
  return groups;
}

}  // namespace

FrameSource parseFrameSource(const std::string& name) {
  if (name == "auto") return FrameSource::Auto;
  if (name == "lmo") return FrameSource::Lmo;
  if (name == "icbin") return FrameSource::Icbin;
  if (name == "synthetic") return FrameSource::Synthetic;
  throw InputError("frame source '" + name + "' is none of auto, lmo, icbin, synthetic");
}

DetectBenchReport runDetectBenchmark(const DetectBenchOptions& o, const GpuOptions& gpu_options,
                                     const BenchProgress& progress) {
  if (o.banks.empty()) throw InputError("bench detect needs at least one --bank");
  if (o.frames < 1) throw InputError(fmt::format("--frames must be 1 or more, not {}", o.frames));
  if (o.warmup < 0) throw InputError(fmt::format("--warmup must be 0 or more, not {}", o.warmup));
  if (o.instances < 0 || o.instances > 50)
    throw InputError(fmt::format("instances per object must be 0 (1 to 2) to 50, not {}", o.instances));
  for (const auto& path : o.banks)
    if (!fs::exists(path)) throw InputError("bank '" + path + "' does not exist");
  validateDetectorParams(o.params);
  auto report_progress = [&](const std::string& phase, std::size_t done, std::size_t total) {
    if (progress) progress(phase, done, total);
  };

  std::vector<TemplateBank> banks;
  for (std::size_t i = 0; i < o.banks.size(); ++i) {
    banks.push_back(loadBank(o.banks[i]));
    report_progress("loading banks", i + 1, o.banks.size());
  }
  DetectBenchReport report;
  for (const auto& b : banks) report.objects.push_back(b.object);

  const fs::path data = o.data_dir.empty() ? fs::path(VKPOSE_SHARED_DATA_DIR) : fs::path(o.data_dir);
  const fs::path lmo = data / "lmo_scene2_frame3", icbin = data / "icbin";
  FrameSource source = o.source;
  if (source == FrameSource::Auto)
    source = lmoObjects(banks, lmo) && fs::exists(lmo / "test")  ? FrameSource::Lmo
             : icbinObjects(banks) && fs::exists(icbin / "camera.json") ? FrameSource::Icbin
                                                                        : FrameSource::Synthetic;

  GpuContext ctx(gpu_options);
  report.device = ctx.device().name;
  std::vector<BenchFrame> frames;
  if (source == FrameSource::Lmo) frames = lmoFrames(lmo, report.frames_from);
  else if (source == FrameSource::Icbin) frames = icbinFrames(icbin, banks, report.frames_from);
  else frames = syntheticFrames(ctx, banks, std::min(o.frames, 8), o.seed, o.instances, report.frames_from);
  report.frames = o.frames;
  report.warmup = o.warmup;
  report.distinct_frames = static_cast<int>(frames.size());
  if (o.no_depth) {
    for (BenchFrame& f : frames) f.frame.depth_mm = cv::Mat();  // colour only
    report.frames_from += ", depth dropped (colour only)";
  }

  std::vector<LinemodTemplate> templates;
  std::vector<int> colour_ids;
  if (o.run_opencv) templates = o.no_depth ? colourTemplates(banks, colour_ids) : concatenateTemplates(banks);
  FeatureParams features = banks.front().params.features;
  features.use_depth = features.use_depth && !o.no_depth;
  gpu::resetBufferPeak();
  Detector detector(ctx, std::move(banks), o.params);
  report.templates = 0;
  for (const auto& b : detector.banks()) report.templates += b.templates.size();

  std::map<std::string, std::vector<double>> times;
  std::map<std::string, double> kernel_sum;  // per stage group, over the timed frames
  std::vector<double> totals, match_ms;
  std::vector<std::size_t> detections;  // per timed frame, to compare with frames in flight
  uint64_t pairs = 0, pruned = 0, skipped = 0;
  double refine_cpu_ms = 0, refined = 0, accepted = 0;
  for (int i = 0; i < o.warmup; ++i) {
    const DetectionResult r = detector.detect(frames[0].frame, frames[0].camera);
    for (const auto& [stage, ms] : r.timings_ms)
      if (stage == stageName(Stage::upload)) report.upload_ms += ms;
    report_progress("warm-up", static_cast<std::size_t>(i + 1), static_cast<std::size_t>(o.warmup));
  }
  for (int i = 0; i < o.frames; ++i) {
    const BenchFrame& f = frames[static_cast<std::size_t>(i) % frames.size()];
    const DetectionResult r = detector.detect(f.frame, f.camera);
    if (i == 0)
      for (const auto& w : r.warnings) report.warnings.push_back(w);
    std::map<std::string, double> by_name(r.timings_ms.begin(), r.timings_ms.end());
    const std::map<std::string, double> kernel_by_name(r.kernel_ms.begin(), r.kernel_ms.end());
    const double upload = by_name.count(stageName(Stage::upload)) ? by_name[stageName(Stage::upload)] : 0.0;
    report.upload_ms += upload;
    for (const auto& stages : stageGroups()) {
      const std::string group = stageName(stages.front());
      double ms = 0;
      bool ran = false;
      for (const Stage stage : stages) {
        const std::string n = stageName(stage);
        if (by_name.count(n)) ms += by_name[n], ran = true;
        if (const auto k = kernel_by_name.find(n); k != kernel_by_name.end()) kernel_sum[group] += k->second;
      }
      if (ran) times[group].push_back(ms);
    }
    totals.push_back(by_name[stageName(Stage::total)] - upload);
    double match = 0;
    for (const Stage stage : {Stage::depth_pruning, Stage::features, Stage::similarity, Stage::match_readback})
      match += by_name[stageName(stage)];
    match_ms.push_back(match);
    pairs += r.match_pairs;
    pruned += r.match_pairs_pruned;
    skipped += r.match_pairs_skipped;
    report.mean_matches += static_cast<double>(r.matches) / o.frames;
    report.mean_hypotheses += static_cast<double>(r.hypotheses) / o.frames;
    report.mean_detections += static_cast<double>(r.detections.size()) / o.frames;
    detections.push_back(r.detections.size());
    refine_cpu_ms += r.refine_cpu_ms;
    report.pose_wall_ms += r.pose_wall_ms / o.frames;
    report.pose_cpu_ms += r.pose_cpu_ms / o.frames;
    report.pose_threads = std::max(report.pose_threads, r.pose_threads);
    refined += static_cast<double>(r.refined_candidates);
    accepted += static_cast<double>(r.detections.size());
    report_progress("detect", static_cast<std::size_t>(i + 1), static_cast<std::size_t>(o.frames));
  }
  for (const auto& stages : stageGroups())
    if (const auto it = times.find(stageName(stages.front())); it != times.end()) {
      const std::string group = it->first;
      double sum = 0;
      for (const double t : it->second) sum += t;
      const double mean = sum / o.frames, kernel = kernel_sum[group] / o.frames;
      report.stages.push_back({group, median(it->second), percentile(it->second, 95), mean, kernel, mean - kernel});
    }
  if (pairs > 0) {
    report.pruned_share = static_cast<double>(pruned) / static_cast<double>(pairs);
    report.skipped_share = static_cast<double>(skipped) / static_cast<double>(pairs);
  }
  report.mean_refined = refined / o.frames;
  report.refine_ms_per_candidate = refined > 0 ? refine_cpu_ms / refined : 0.0;
  report.refined_per_detection = accepted > 0 ? refined / accepted : 0.0;
  double total_sum = 0;
  for (const double t : totals) total_sum += t;
  double kernel_total = 0;
  for (const auto& [group, ms] : kernel_sum) kernel_total += ms / o.frames;
  report.stages.push_back({stageName(Stage::total), median(totals), percentile(totals, 95), total_sum / o.frames, kernel_total,
                           total_sum / o.frames - kernel_total});
  report.frames_per_s = total_sum > 0 ? 1000.0 * o.frames / total_sum : 0.0;
  if (o.in_flight && o.frames > 1) {
    // The same frames again, two in flight: the next frame's stages 1-2 on the GPU while
    // this frame's CPU stages run.
    std::vector<LinemodFrame> sequence;
    std::vector<Camera> cameras;
    for (int i = 0; i < o.frames; ++i) {
      const BenchFrame& f = frames[static_cast<std::size_t>(i) % frames.size()];
      sequence.push_back(f.frame);
      cameras.push_back(f.camera);
    }
    std::vector<DetectionResult> results;
    const double ms = timeMs([&] { results = detector.detectSequence(sequence, cameras); });
    report.frames_per_s_in_flight = ms > 0 ? 1000.0 * o.frames / ms : 0.0;
    for (std::size_t i = 0; i < results.size(); ++i)
      report.in_flight_same_detections = report.in_flight_same_detections && results[i].detections.size() == detections[i];
    report_progress("frames in flight", 1, 1);
  }
  report.vkpose_match_ms = median(match_ms);
  const gpu::BufferMemory gpu_memory = gpu::bufferMemory();
  report.gpu_peak_bytes = gpu_memory.peak;
  report.gpu_live_bytes = gpu_memory.live;

  if (o.run_opencv) {
    // The same templates, threshold and frames, through OpenCV's own LINEMOD matching.
    auto cv_detector = makeOpenCvDetector(features);
    const auto modalities = activeModalities(features);
    for (const auto& t : templates) cv_detector->addSyntheticTemplate(toOpenCvTemplate(t, modalities), "bench");
    std::vector<double> cv_ms;
    double matches = 0;
    for (int i = 0; i < o.frames; ++i) {
      const BenchFrame& f = frames[static_cast<std::size_t>(i) % frames.size()];
      std::vector<cv::Mat> sources;
      if (features.use_colour) sources.push_back(f.frame.bgr);
      if (features.use_depth) sources.push_back(f.frame.depth_mm);
      std::vector<cv::linemod::Match> found;
      cv_ms.push_back(timeMs([&] { cv_detector->match(sources, o.params.match.threshold, found); }));
      matches += static_cast<double>(found.size()) / o.frames;
      report_progress("cv::linemod", static_cast<std::size_t>(i + 1), static_cast<std::size_t>(o.frames));
    }
    report.opencv_match_ms = median(cv_ms);
    report.opencv_matches = static_cast<std::size_t>(matches + 0.5);
    report.opencv_ratio = report.vkpose_match_ms > 0 ? report.opencv_match_ms / report.vkpose_match_ms : 0.0;
  }
  report.peak_rss_bytes = peakResidentBytes();
  return report;
}

std::string formatDetectReport(const DetectBenchReport& r) {
  std::string out;
  std::string objects;
  for (const auto& o : r.objects) objects += (objects.empty() ? "" : ", ") + o;
  out += fmt::format("detector, {} frame{} timed after {} warm-up ({} distinct): {}\n", r.frames,
                     r.frames == 1 ? "" : "s", r.warmup, r.distinct_frames, r.frames_from);
  out += fmt::format("objects: {} ({} templates)\n", objects, r.templates);
  out += fmt::format("device: {}\n\n", r.device);
  out += fmt::format("{:<14} {:>12} {:>12} {:>12} {:>12} {:>12}\n", "stage", "median ms", "p95 ms", "mean ms",
                     "kernel ms", "host ms");
  for (const auto& s : r.stages)
    out += fmt::format("{:<14} {:>12.1f} {:>12.1f} {:>12.1f} {:>12.1f} {:>12.1f}\n", s.stage, s.median_ms, s.p95_ms,
                       s.mean_ms, s.kernel_ms, s.host_ms);
  out += "(kernel: the GPU's own time in the stage, from device timestamps; host: the rest of its mean)\n";
  out += fmt::format("\n{:.3f} frames/s; per frame {:.0f} matches, {:.0f} hypotheses, {:.1f} detections\n",
                     r.frames_per_s, r.mean_matches, r.mean_hypotheses, r.mean_detections);
  if (r.mean_refined > 0)
    out += fmt::format("pose stages: {:.1f} candidates refined a frame, {:.1f} CPU ms each (MLS, ICP, verification on "
                       "one core), {:.1f} refined per detection\n"
                       "pose stages 6-8 a frame: wall {:.1f} ms, CPU {:.1f} ms on {} thread{} (wall / CPU {:.2f})\n",
                       r.mean_refined, r.refine_ms_per_candidate, r.refined_per_detection, r.pose_wall_ms,
                       r.pose_cpu_ms, r.pose_threads, r.pose_threads == 1 ? "" : "s",
                       r.pose_cpu_ms > 0 ? r.pose_wall_ms / r.pose_cpu_ms : 0.0);
  out += r.pruned_share > 0 || r.skipped_share > 0
             ? fmt::format("depth-guided pruning: {:.1f} % of the (template, position) pairs pruned, {:.1f} % skipped "
                           "unread\n",
                           100.0 * r.pruned_share, 100.0 * r.skipped_share)
             : std::string("depth-guided pruning: off\n");
  if (r.frames_per_s_in_flight > 0)
    out += fmt::format("two frames in flight (the next frame's stages 1-2 during this frame's CPU stages): {:.3f} "
                       "frames/s, {:.2f} x frame by frame{}\n",
                       r.frames_per_s_in_flight, r.frames_per_s > 0 ? r.frames_per_s_in_flight / r.frames_per_s : 0.0,
                       r.in_flight_same_detections ? "" : " (DIFFERENT detection counts: a bug)");
  out += fmt::format("template upload (first frame, not in total): {:.1f} ms\n", r.upload_ms);
  if (r.opencv_match_ms > 0)
    out += fmt::format("stages 1-2 vs cv::linemod (same templates, threshold, frames; median): vkpose {:.1f} ms, "
                       "cv::linemod {:.1f} ms ({} matches), ratio {:.2f}\n",
                       r.vkpose_match_ms, r.opencv_match_ms, r.opencv_matches, r.opencv_ratio);
  out += fmt::format("memory: peak resident {}, GPU buffers peak {} (live after the run {})\n",
                     formatBytes(r.peak_rss_bytes), formatBytes(r.gpu_peak_bytes), formatBytes(r.gpu_live_bytes));
  return out;
}

nlohmann::json detectReportJson(const DetectBenchReport& r) {
  nlohmann::json stages = nlohmann::json::object();
  for (const auto& s : r.stages)
    stages[s.stage] = {{"median_ms", s.median_ms}, {"p95_ms", s.p95_ms},       {"mean_ms", s.mean_ms},
                       {"kernel_ms", s.kernel_ms}, {"host_ms", s.host_ms}};
  nlohmann::json j = {{"device", r.device},
                      {"frames_from", r.frames_from},
                      {"frames", r.frames},
                      {"warmup", r.warmup},
                      {"distinct_frames", r.distinct_frames},
                      {"objects", r.objects},
                      {"templates", r.templates},
                      {"stages", stages},
                      {"frames_per_s", r.frames_per_s},
                      {"frames_per_s_in_flight", r.frames_per_s_in_flight},
                      {"upload_ms", r.upload_ms},
                      {"mean_matches", r.mean_matches},
                      {"mean_hypotheses", r.mean_hypotheses},
                      {"mean_detections", r.mean_detections},
                      {"mean_refined_candidates", r.mean_refined},
                      {"refine_cpu_ms_per_candidate", r.refine_ms_per_candidate},
                      {"refined_per_detection", r.refined_per_detection},
                      {"pose_stages", {{"wall_ms", r.pose_wall_ms},
                                       {"cpu_ms", r.pose_cpu_ms},
                                       {"threads", r.pose_threads},
                                       {"wall_to_cpu", r.pose_cpu_ms > 0 ? r.pose_wall_ms / r.pose_cpu_ms : 0.0}}},
                      {"pruned_share", r.pruned_share},
                      {"skipped_share", r.skipped_share},
                      {"memory", {{"peak_rss_bytes", r.peak_rss_bytes},
                                  {"gpu_peak_bytes", r.gpu_peak_bytes},
                                  {"gpu_live_bytes", r.gpu_live_bytes}}},
                      {"warnings", r.warnings}};
  if (r.opencv_match_ms > 0)
    j["opencv"] = {{"match_ms", r.opencv_match_ms},
                   {"vkpose_stages_1_2_ms", r.vkpose_match_ms},
                   {"ratio", r.opencv_ratio},
                   {"matches", r.opencv_matches}};
  return j;
}

std::vector<DetectSweepRow> runDetectSweep(const DetectBenchOptions& options, DetectSweep sweep,
                                           const std::vector<int>& counts, const GpuOptions& gpu,
                                           const BenchProgress& progress) {
  if (counts.empty()) throw InputError("a sweep needs at least one count");
  for (const int n : counts)
    if (n < 1 || n > (sweep == DetectSweep::Objects ? 100 : 50))
      throw InputError(fmt::format("sweep count {} is outside 1..{}", n, sweep == DetectSweep::Objects ? 100 : 50));
  if (options.banks.empty()) throw InputError("bench detect needs at least one --bank");
  std::vector<DetectSweepRow> rows;
  for (const int n : counts) {
    DetectBenchOptions o = options;
    o.run_opencv = false;
    o.in_flight = false;
    if (sweep == DetectSweep::Objects) {
      o.banks.clear();
      for (int i = 0; i < n; ++i) o.banks.push_back(options.banks[static_cast<std::size_t>(i) % options.banks.size()]);
    } else {
      o.source = FrameSource::Synthetic;
      o.instances = n;
    }
    const std::string label = sweep == DetectSweep::Objects ? fmt::format("{} objects", n) : fmt::format("{} instances", n);
    const DetectBenchReport r = runDetectBenchmark(o, gpu, [&](const std::string& phase, std::size_t done, std::size_t total) {
      if (progress) progress(label + ": " + phase, done, total);
    });
    DetectSweepRow row;
    row.objects = static_cast<int>(o.banks.size());
    row.instances = o.instances;
    row.templates = r.templates;
    for (const auto& st : r.stages) {
      if (st.stage == stageName(Stage::total)) row.total_ms = st.median_ms;
      else if (isPoseStage(st.stage))
        row.pose_ms += st.median_ms;
      else row.match_ms += st.median_ms;
    }
    row.matches = r.mean_matches;
    row.detections = r.mean_detections;
    row.pruned_share = r.pruned_share;
    row.device = r.device;
    row.frames_from = r.frames_from;
    rows.push_back(row);
  }
  return rows;
}

std::string formatDetectSweep(const std::vector<DetectSweepRow>& rows, DetectSweep sweep) {
  std::string out;
  if (!rows.empty()) out += fmt::format("device: {}\nframes: {}\n\n", rows.front().device, rows.front().frames_from);
  out += fmt::format("{:>9} {:>10} {:>11} {:>14} {:>14} {:>9} {:>11} {:>8}\n",
                     sweep == DetectSweep::Objects ? "objects" : "instances", "templates", "total ms",
                     "stages 1-5 ms", "stages 6-8 ms", "matches", "detections", "pruned");
  for (const auto& r : rows)
    out += fmt::format("{:>9} {:>10} {:>11.1f} {:>14.1f} {:>14.1f} {:>9.0f} {:>11.1f} {:>7.1f}%\n",
                       sweep == DetectSweep::Objects ? r.objects : r.instances, r.templates, r.total_ms, r.match_ms,
                       r.pose_ms, r.matches, r.detections, 100.0 * r.pruned_share);
  out += "(medians per frame; stages 1-5: features to NMS, 6-8: poses and verification)\n";
  return out;
}

nlohmann::json detectSweepJson(const std::vector<DetectSweepRow>& rows, DetectSweep sweep) {
  nlohmann::json points = nlohmann::json::array();
  for (const auto& r : rows)
    points.push_back({{"objects", r.objects},
                      {"instances", r.instances},
                      {"templates", r.templates},
                      {"total_ms", r.total_ms},
                      {"stages_1_5_ms", r.match_ms},
                      {"stages_6_8_ms", r.pose_ms},
                      {"matches", r.matches},
                      {"detections", r.detections},
                      {"pruned_share", r.pruned_share}});
  return {{"sweep", sweep == DetectSweep::Objects ? "objects" : "instances"},
          {"device", rows.empty() ? "" : rows.front().device},
          {"frames_from", rows.empty() ? "" : rows.front().frames_from},
          {"points", points}};
}

std::string detectSweepSvg(const std::vector<DetectSweepRow>& rows, DetectSweep sweep) {
  PlotSeries total{"whole frame", "#1f77b4", {}}, match{"stages 1-5 (matching to NMS)", "#2ca02c", {}},
      pose{"stages 6-8 (poses, verification)", "#d62728", {}};
  for (const auto& r : rows) {
    const double x = sweep == DetectSweep::Objects ? r.objects : r.instances;
    total.points.emplace_back(x, r.total_ms);
    match.points.emplace_back(x, r.match_ms);
    pose.points.emplace_back(x, r.pose_ms);
  }
  PlotSpec spec;
  spec.title = fmt::format("vkpose detect, {}", rows.empty() ? "" : rows.front().device);
  spec.x_label = sweep == DetectSweep::Objects ? "objects (banks searched per frame)" : "instances of each object per frame";
  spec.y_label = "median ms per frame";
  spec.log_y = true;
  spec.series = {total, match, pose};
  return svgLinePlot(spec);
}

}  // namespace vkpose::bench
