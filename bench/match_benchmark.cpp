#include "bench/match_benchmark.hpp"

#include <algorithm>
#include <filesystem>
#include <iostream>
#include <random>

#include <fmt/format.h>
#include <opencv2/imgproc.hpp>

#include "bench/bench_support.hpp"
#include "gpu/buffer.hpp"
#include "match/features.hpp"
#include "match/matcher.hpp"
#include "match/opencv_linemod.hpp"
#include "vkpose/bank.hpp"
#include "vkpose/device.hpp"
#include "vkpose/error.hpp"
#include "vkpose/frame.hpp"

namespace vkpose::bench {

namespace {

/// A synthetic tabletop frame: boxes and discs at several depths on a plane.
LinemodFrame syntheticFrame() {
  LinemodFrame f;
  f.bgr = cv::Mat(480, 640, CV_8UC3, cv::Scalar(90, 100, 110));
  f.depth_mm = cv::Mat(480, 640, CV_16UC1, cv::Scalar(900));
  std::mt19937 rng(7);
  std::uniform_int_distribution<int> px(20, 600), py(20, 440), sz(20, 70), col(0, 255), dep(600, 850);
  for (int i = 0; i < 25; ++i) {
    const cv::Scalar c(col(rng), col(rng), col(rng));
    const int x = px(rng), y = py(rng), s = sz(rng), d = dep(rng);
    if (i % 2) {
      cv::rectangle(f.bgr, {x, y, s, s}, c, cv::FILLED);
      cv::rectangle(f.depth_mm, {x, y, s, s}, cv::Scalar(d), cv::FILLED);
    } else {
      cv::circle(f.bgr, {x, y}, s / 2, c, cv::FILLED);
      cv::circle(f.depth_mm, {x, y}, s / 2, cv::Scalar(d), cv::FILLED);
    }
  }
  return f;
}

/// A variant of `base`: features moved by up to one pixel and, now and then, turned by one
/// bin, so that jittered copies still match near where their original matches.
LinemodTemplate jitter(const LinemodTemplate& base, std::mt19937& rng) {
  LinemodTemplate t = base;
  std::uniform_int_distribution<int> step(-1, 1), turn(0, 9);
  for (auto& level : t.levels)
    for (auto& f : level.features) {
      f.x = std::clamp(f.x + step(rng), 0, std::max(0, level.width));
      f.y = std::clamp(f.y + step(rng), 0, std::max(0, level.height));
      if (turn(rng) == 0) f.bin = static_cast<uint8_t>((f.bin + (step(rng) & 7)) & 7);
    }
  return t;
}

}  // namespace

std::vector<MatchBenchRow> runMatchBenchmark(const MatchBenchOptions& o, const GpuOptions& gpu_options,
                                             std::string& frame_description) {
  LinemodFrame frame;
  std::string rgb = o.rgb, depth = o.depth;
  const std::string lmo = std::string(VKPOSE_SHARED_DATA_DIR) + "/lmo_scene2_frame3/test/000002/";
  if (rgb.empty() && std::filesystem::exists(lmo + "rgb/000003.png")) {
    rgb = lmo + "rgb/000003.png";
    depth = lmo + "depth/000003.png";
  }
  if (!rgb.empty()) {
    frame = loadFrame(rgb, depth);
    frame_description = rgb;
  } else {
    frame = syntheticFrame();
    frame_description = "synthetic 640x480 frame (../shared/data not found)";
  }

  FeatureParams fp;
  MatchParams mp;
  mp.threshold = o.threshold;
  const auto modalities = activeModalities(fp);

  std::vector<int> counts = o.template_counts;
  if (o.sweep == MatchSweep::Objects) {
    counts.clear();
    for (const int n : o.object_counts) counts.push_back(n * o.templates_per_object);
  }
  const int wanted = *std::max_element(counts.begin(), counts.end());
  std::vector<LinemodTemplate> templates;
  std::vector<int> object_templates;  // the objects sweep: templates per object
  if (o.sweep == MatchSweep::Objects && !o.bank.empty()) {
    // Each object a copy of the bank's templates (as if the same object were trained again).
    const TemplateBank bank = loadBank(o.bank);
    if (bank.params.features.T != fp.T || bank.params.features.use_colour != fp.use_colour ||
        bank.params.features.use_depth != fp.use_depth)
      throw InputError("bank '" + o.bank + "' was trained with another pyramid or other modalities than the benchmark's");
    const std::vector<LinemodTemplate> one = bank.linemodTemplates();
    counts.clear();
    for (const int n : o.object_counts) counts.push_back(n * static_cast<int>(one.size()));
    const int objects = *std::max_element(o.object_counts.begin(), o.object_counts.end());
    templates.reserve(one.size() * static_cast<std::size_t>(objects));
    for (int k = 0; k < objects; ++k) templates.insert(templates.end(), one.begin(), one.end());
  } else {
    // Base templates cut by OpenCV's own extraction from regions of the frame, then jittered
    // copies up to the largest count. Both sides get exactly the same templates.
    std::mt19937 rng(42);
    std::vector<cv::Rect> regions;
    std::uniform_int_distribution<int> size(48, 160);
    for (int i = 0; i < 160; ++i) {
      const int w = size(rng), h = size(rng);
      std::uniform_int_distribution<int> x(0, frame.bgr.cols - w), y(0, frame.bgr.rows - h);
      regions.emplace_back(x(rng), y(rng), w, h);
    }
    auto extractor = makeOpenCvDetector(fp);
    templates = extractOpenCvTemplates(*extractor, frame, regions, fp);
    if (templates.empty()) throw InputError("no LINEMOD templates could be cut from " + frame_description);
    const std::size_t base_count = templates.size();
    templates.reserve(static_cast<std::size_t>(wanted));
    while (templates.size() < static_cast<std::size_t>(wanted))
      templates.push_back(jitter(templates[rng() % base_count], rng));
  }

  GpuContext ctx(gpu_options);
  std::vector<MatchBenchRow> rows;
  for (std::size_t c = 0; c < counts.size(); ++c) {
    const int count = counts[c];
    if (o.progress) std::cerr << "bench match: " << count << " templates ..." << std::flush;
    MatchBenchRow row;
    row.templates = count;
    row.objects = o.sweep == MatchSweep::Objects ? o.object_counts[c] : 0;
    row.device = ctx.device().name;

    std::vector<double> times;
    {
      gpu::resetBufferPeak();
      LinemodMatcher matcher(ctx, fp, mp);
      matcher.setTemplates({templates.begin(), templates.begin() + count});
      std::vector<Match> ours = matcher.match(frame);  // warm-up, uploads templates
      row.stages = {{"features"}, {"similarity"}, {"match_readback"}};
      for (int r = 0; r < o.repeats; ++r) {
        times.push_back(timeMs([&] { ours = matcher.match(frame); }));
        const MatchTimings& t = matcher.lastTimings();
        const double n = o.repeats;
        row.stages[0].ms += t.features_ms / n, row.stages[0].kernel_ms += t.features_kernel_ms / n;
        row.stages[1].ms += (t.pruning_ms + t.similarity_ms) / n, row.stages[1].kernel_ms += t.similarity_kernel_ms / n;
        row.stages[2].ms += t.finish_ms / n;
      }
      row.vkpose_ms = median(times);
      row.vkpose_matches = ours.size();
      row.passes = matcher.lastTimings().passes;
      row.attempts = matcher.lastTimings().attempts;
      row.coarse_candidates = matcher.lastTimings().coarse_candidates;
      row.gpu_peak_bytes = gpu::bufferMemory().peak;
      row.rss_bytes = residentBytes();
    }

    if (o.run_opencv) {
      auto detector = makeOpenCvDetector(fp);
      for (int i = 0; i < count; ++i)
        detector->addSyntheticTemplate(toOpenCvTemplate(templates[static_cast<std::size_t>(i)], modalities), "bench");
      std::vector<cv::Mat> sources{frame.bgr, frame.depth_mm};
      std::vector<cv::linemod::Match> theirs;
      detector->match(sources, o.threshold, theirs);
      times.clear();
      for (int r = 0; r < o.repeats; ++r) times.push_back(timeMs([&] { detector->match(sources, o.threshold, theirs); }));
      row.opencv_ms = median(times);
      row.opencv_matches = theirs.size();
      row.ratio = row.opencv_ms / row.vkpose_ms;
    }
    // VmHWM lags VmRSS by a few pages: the peak is at least every resident figure seen.
    row.peak_rss_bytes = std::max({peakResidentBytes(), row.rss_bytes, rows.empty() ? 0 : rows.back().peak_rss_bytes});
    if (o.progress) std::cerr << " done\n";
    rows.push_back(row);
  }
  return rows;
}

std::vector<int> templateSweepCounts() { return {1000, 3000, 10000, 30000, 100000}; }

std::string matchSweepSvg(const std::vector<MatchBenchRow>& rows, const std::string& frame_description) {
  const bool objects = !rows.empty() && rows.front().objects > 0;
  PlotSeries ours{"vkpose", "#1f77b4", {}}, theirs{"cv::linemod", "#d62728", {}};
  for (const auto& r : rows) {
    const double x = objects ? r.objects : r.templates;
    ours.points.emplace_back(x, r.vkpose_ms);
    if (r.opencv_ms > 0) theirs.points.emplace_back(x, r.opencv_ms);
  }
  PlotSpec spec;
  spec.title = fmt::format("LINEMOD matching, {}", rows.empty() ? "" : rows.front().device);
  spec.x_label = objects ? fmt::format("objects ({} templates each)", rows.front().templates / rows.front().objects)
                         : "templates";
  spec.y_label = "median ms per frame";
  spec.log_y = true;
  spec.series.push_back(ours);
  if (!theirs.points.empty()) spec.series.push_back(theirs);
  std::string svg = svgLinePlot(spec);
  // The frame, as a comment: where the numbers came from.
  std::string what = frame_description;
  for (std::size_t at; (at = what.find("--")) != std::string::npos;) what.replace(at, 2, "- -");  // not in a comment
  const std::string comment = "<!-- frame: " + what + " -->\n";
  return svg.insert(svg.find('\n') + 1, comment);
}

}  // namespace vkpose::bench
