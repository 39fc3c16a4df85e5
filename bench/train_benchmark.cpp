#include "bench/train_benchmark.hpp"

#include <chrono>
#include <filesystem>

#include <opencv2/imgproc.hpp>
#include <opencv2/rgbd/linemod.hpp>

#include "match/features.hpp"
#include "match/matcher.hpp"
#include "match/opencv_linemod.hpp"
#include "render/render.hpp"
#include "training/training.hpp"
#include "util/progress.hpp"
#include "vkpose/bank.hpp"
#include "vkpose/device.hpp"
#include "vkpose/geometry.hpp"

namespace vkpose::bench {

namespace {
double secondsSince(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

/// An icosphere-like test object when no mesh is at hand: a unit-radius sphere scaled to 10 cm.
Mesh fallbackMesh() {
  Mesh m;
  m.name = "sphere";
  const int rings = 48, segments = 96;
  for (int r = 0; r <= rings; ++r)
    for (int s = 0; s < segments; ++s) {
      const double th = CV_PI * r / rings, ph = 2 * CV_PI * s / segments;
      m.vertices.emplace_back(static_cast<float>(0.05 * std::sin(th) * std::cos(ph)),
                              static_cast<float>(0.05 * std::sin(th) * std::sin(ph)), static_cast<float>(0.05 * std::cos(th)));
    }
  for (int r = 0; r < rings; ++r)
    for (int s = 0; s < segments; ++s) {
      const int a = r * segments + s, b = r * segments + (s + 1) % segments;
      m.faces.emplace_back(a, a + segments, b);
      m.faces.emplace_back(b, a + segments, b + segments);
    }
  finishMesh(m);
  return m;
}
}  // namespace

TrainBenchResult runTrainBenchmark(const TrainBenchOptions& options, const GpuOptions& gpu) {
  TrainBenchResult out;
  std::string path = options.mesh;
  if (path.empty() && std::filesystem::exists(VKPOSE_SHARED_DATA_DIR "/meshes/coffee_cup.stl"))
    path = VKPOSE_SHARED_DATA_DIR "/meshes/coffee_cup.stl";
  const Mesh mesh = path.empty() ? fallbackMesh() : loadMesh(path);
  out.mesh = path.empty() ? "generated sphere (../shared/data absent)" : path;
  GpuContext ctx(gpu);
  out.device = ctx.device().name;
  TrainingParams params;
  params.views.viewpoints = options.viewpoints;

  // vkpose: the whole training, as `vkpose train` runs it.
  util::ProgressBar bar("training", !options.progress);
  TrainingTimings timings;
  const auto t0 = std::chrono::steady_clock::now();
  const TemplateBank bank =
      trainTemplates(ctx, mesh, params, [&](std::size_t d, std::size_t n) { bar.update(d, n); }, &timings);
  out.total_s = secondsSince(t0);
  bar.finish();
  out.templates = bank.templates.size();
  out.render_s = timings.render_ms / 1e3;
  out.features_s = timings.features_ms / 1e3;
  out.templates_per_s = static_cast<double>(out.templates) / out.total_s;

  // The same training with the views quantized one by one by the CPU reference (how training
  // ran before its quantization moved to the GPU), for the ratio in the same run.
  if (options.reference) {
    util::ProgressBar ref_bar("training, CPU quantization", !options.progress);
    TrainingTimings ref;
    const auto t_ref = std::chrono::steady_clock::now();
    const TemplateBank ref_bank =
        trainTemplatesWith(ctx, mesh, params, sampleViews(params.views, mesh.bboxCentre()),
                           FeatureQuantization::cpu_reference, [&](std::size_t d, std::size_t n) { ref_bar.update(d, n); },
                           &ref);
    out.reference_total_s = secondsSince(t_ref);
    ref_bar.finish();
    out.reference_features_s = ref.features_ms / 1e3;
    out.reference_identical = ref_bank.templates.size() == bank.templates.size();
    for (std::size_t i = 0; out.reference_identical && i < bank.templates.size(); ++i)
      out.reference_identical = bank.templates[i].linemod == ref_bank.templates[i].linemod;
  }

  // Same renderings for both: the first views, each rendered (not rotated) on the GPU.
  auto views = sampleViews(params.views, mesh.bboxCentre());
  views.resize(std::min<std::size_t>(views.size(), static_cast<std::size_t>(options.opencv_templates)));
  if (views.empty()) return out;
  const Camera tile = trainingCamera(mesh, params, views);
  std::vector<Pose> poses;
  for (const auto& v : views) poses.push_back({v.R, v.t});
  MeshRenderer renderer(ctx, mesh);
  const auto renders = renderer.render(tile, poses);
  auto t1 = std::chrono::steady_clock::now();
  for (const auto& r : renders) (void)extractTemplate(r, params);
  out.vkpose_features_ms = 1e3 * secondsSince(t1) / static_cast<double>(renders.size());

  auto detector = makeOpenCvDetector(params.features);
  std::vector<std::pair<cv::Mat, cv::Mat>> sources;
  for (const auto& r : renders) {
    sources.emplace_back(r.bgr, depthMillimetres(r.depth));
  }
  t1 = std::chrono::steady_clock::now();
  for (std::size_t i = 0; i < renders.size(); ++i) {
    const std::vector<cv::Mat> src = {sources[i].first, sources[i].second};
    cv::Rect box;
    // OpenCV refuses a view (-1) when a modality finds fewer than 63 features.
    if (detector->addTemplate(src, "object", renders[i].mask(), &box) < 0) ++out.opencv_refused;
  }
  out.opencv_templates = renders.size();
  out.opencv_ms = 1e3 * secondsSince(t1) / static_cast<double>(renders.size());
  out.ratio = out.opencv_ms / (1e3 * out.total_s / static_cast<double>(out.templates));
  return out;
}

}  // namespace vkpose::bench
