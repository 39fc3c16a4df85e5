#include "bench/match_benchmark.hpp"

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <iostream>
#include <random>

#include <opencv2/imgproc.hpp>

#include "vkpose/error.hpp"
#include "vkpose/frame_io.hpp"
#include "vkpose/matcher.hpp"
#include "vkpose/opencv_linemod.hpp"

namespace vkpose::bench {

namespace {

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.empty() ? 0.0 : v[v.size() / 2];
}

template <class F>
double timeMs(F&& f) {
  const auto t0 = std::chrono::steady_clock::now();
  f();
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

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

  // Base templates cut by OpenCV's own extraction from regions of the frame, then jittered
  // copies up to the largest count. Both sides get exactly the same templates.
  const int wanted = *std::max_element(o.template_counts.begin(), o.template_counts.end());
  std::mt19937 rng(42);
  std::vector<cv::Rect> regions;
  std::uniform_int_distribution<int> size(48, 160);
  for (int i = 0; i < 160; ++i) {
    const int w = size(rng), h = size(rng);
    std::uniform_int_distribution<int> x(0, frame.bgr.cols - w), y(0, frame.bgr.rows - h);
    regions.emplace_back(x(rng), y(rng), w, h);
  }
  auto extractor = makeOpenCvDetector(fp);
  std::vector<LinemodTemplate> templates = extractOpenCvTemplates(*extractor, frame, regions, fp);
  if (templates.empty()) throw InputError("no LINEMOD templates could be cut from " + frame_description);
  const std::size_t base_count = templates.size();
  while (templates.size() < static_cast<std::size_t>(wanted))
    templates.push_back(jitter(templates[rng() % base_count], rng));

  GpuContext ctx(gpu_options);
  std::vector<MatchBenchRow> rows;
  for (int count : o.template_counts) {
    if (o.progress) std::cerr << "bench match: " << count << " templates ..." << std::flush;
    std::vector<LinemodTemplate> subset(templates.begin(), templates.begin() + count);
    MatchBenchRow row;
    row.templates = count;
    row.device = ctx.device().name;

    LinemodMatcher matcher(ctx, fp, mp);
    matcher.setTemplates(subset);
    std::vector<Match> ours = matcher.match(frame);  // warm-up, uploads templates
    std::vector<double> times;
    for (int r = 0; r < o.repeats; ++r) times.push_back(timeMs([&] { ours = matcher.match(frame); }));
    row.vkpose_ms = median(times);
    row.vkpose_matches = ours.size();

    if (o.run_opencv) {
      auto detector = makeOpenCvDetector(fp);
      for (const auto& t : subset) detector->addSyntheticTemplate(toOpenCvTemplate(t, modalities), "bench");
      std::vector<cv::Mat> sources{frame.bgr, frame.depth_mm};
      std::vector<cv::linemod::Match> theirs;
      detector->match(sources, o.threshold, theirs);
      times.clear();
      for (int r = 0; r < o.repeats; ++r) times.push_back(timeMs([&] { detector->match(sources, o.threshold, theirs); }));
      row.opencv_ms = median(times);
      row.opencv_matches = theirs.size();
      row.ratio = row.opencv_ms / row.vkpose_ms;
    }
    if (o.progress) std::cerr << " done\n";
    rows.push_back(row);
  }
  return rows;
}

}  // namespace vkpose::bench
