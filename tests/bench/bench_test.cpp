// The benchmarks' pure parts (percentiles, the SVG plot) and `bench detect` end to end on one
// synthetic frame of a small bank.
#include <algorithm>
#include <filesystem>
#include <thread>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "bench/bench_support.hpp"
#include "bench/detect_benchmark.hpp"
#include "bench/match_benchmark.hpp"
#include "mesh_support.hpp"
#include "test_support.hpp"
#include "vkpose/error.hpp"

namespace vkpose {
namespace {

TEST(BenchSupport, PercentilesInterpolateBetweenRanks) {
  EXPECT_DOUBLE_EQ(bench::median({4, 1, 3, 2}), 2.5);
  EXPECT_DOUBLE_EQ(bench::median({5, 1, 3}), 3.0);
  EXPECT_DOUBLE_EQ(bench::median({}), 0.0);
  std::vector<double> v;
  for (int i = 1; i <= 20; ++i) v.push_back(i);
  EXPECT_NEAR(bench::percentile(v, 95), 19.05, 1e-12);  // rank 0.95 * 19 = 18.05
  EXPECT_DOUBLE_EQ(bench::percentile(v, 0), 1.0);
  EXPECT_DOUBLE_EQ(bench::percentile(v, 100), 20.0);
  EXPECT_DOUBLE_EQ(bench::percentile({7}, 95), 7.0);
}

TEST(BenchSupport, FormatsBytes) {
  EXPECT_EQ(bench::formatBytes(512), "512 B");
  EXPECT_EQ(bench::formatBytes(3 * 1024), "3 KiB");
  EXPECT_EQ(bench::formatBytes(3 * 1024 * 1024 / 2), "1.5 MiB");
  EXPECT_GT(bench::peakResidentBytes(), 1024u * 1024u);  // this process holds more than a MiB
  EXPECT_GE(bench::peakResidentBytes(), bench::residentBytes());
}

TEST(BenchSupport, SvgPlotPlacesPointsOnLogAxes) {
  bench::PlotSpec spec;
  spec.title = "a < b & c";
  spec.x_label = "templates";
  spec.y_label = "ms";
  spec.log_y = true;
  spec.series.push_back({"vkpose", "#1f77b4", {{10, 1}, {100, 10}, {1000, 100}}});
  spec.series.push_back({"cv::linemod", "#d62728", {{10, 2}, {1000, 0}}});  // y 0 cannot sit on a log axis
  const std::string svg = bench::svgLinePlot(spec);
  EXPECT_EQ(svg.rfind("<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"640\" height=\"420\"", 0), 0u);
  EXPECT_NE(svg.find("</svg>"), std::string::npos);
  // 640 x 420 with margins 80 / 20 / 40 / 60: the plot spans x 80..620 and y 40..360, one
  // decade per 270 px across and per 160 px up.
  EXPECT_NE(svg.find("points=\"80.0,360.0 350.0,200.0 620.0,40.0\""), std::string::npos) << svg;
  EXPECT_NE(svg.find("points=\"80.0,311.8\""), std::string::npos) << svg;  // log10(2) * 160 above the bottom
  for (const char* label : {">vkpose<", ">cv::linemod<", ">10<", ">100<", ">1k<", ">a &lt; b &amp; c<",
                            ">templates (log scale)<", ">ms (log scale)<"})
    EXPECT_NE(svg.find(label), std::string::npos) << label;
  EXPECT_EQ(svg.find("a < b"), std::string::npos);

  spec.series = {{"none", "#000", {{0, 1}, {-5, 2}}}};
  EXPECT_THROW(bench::svgLinePlot(spec), std::invalid_argument);
}

TEST(BenchSupport, MatchSweepPlotHasBothLines) {
  std::vector<bench::MatchBenchRow> rows(2);
  rows[0].templates = 14040, rows[0].objects = 1, rows[0].vkpose_ms = 1500, rows[0].opencv_ms = 1600;
  rows[1].templates = 28080, rows[1].objects = 2, rows[1].vkpose_ms = 3000, rows[1].opencv_ms = 3300;
  const std::string svg = bench::matchSweepSvg(rows, "frame --x");
  EXPECT_NE(svg.find(">objects (14040 templates each) (log scale)<"), std::string::npos) << svg;
  EXPECT_NE(svg.find("<!-- frame: frame - -x -->"), std::string::npos);
  std::size_t lines = 0;
  for (std::size_t at = 0; (at = svg.find("<polyline", at)) != std::string::npos; ++at) ++lines;
  EXPECT_EQ(lines, 2u);
}

/// A small bank of a box (no shared data needed): 18 templates.
std::string smallBoxBank() {
  static const std::string path = [] {
    Mesh box = test::boxMesh({0.08f, 0.05f, 0.12f});
    box.name = "box";
    box.colours.assign(box.vertices.size(), Eigen::Vector3f(0.8f, 0.3f, 0.2f));
    TrainingParams params;
    params.views.viewpoints = 6;
    params.views.radii = {0.6f, 0.7f, 0.1f};
    params.views.inplane_deg = {-10.f, 10.f, 10.f};
    params.camera.cx = 319.5, params.camera.cy = 239.5;
    const std::string p = test::scratchDir("vkpose_bench_") + "/box.vkpb";
    saveBank(trainTemplates(test::context(), box, params), p);
    return p;
  }();
  return path;
}

// The small box bank on one synthetic frame, no warm-up.
bench::DetectBenchOptions oneSyntheticFrame() {
  bench::DetectBenchOptions o;
  o.banks = {smallBoxBank()};
  o.frames = 1;
  o.warmup = 0;
  o.source = bench::FrameSource::Synthetic;
  return o;
}

TEST(BenchDetect, OneSyntheticFrameReportsEveryStage) {
  const bench::DetectBenchOptions o = oneSyntheticFrame();
  std::vector<std::string> phases;
  const bench::DetectBenchReport r =
      bench::runDetectBenchmark(o, {}, [&](const std::string& phase, std::size_t, std::size_t) {
        if (phases.empty() || phases.back() != phase) phases.push_back(phase);
      });
  EXPECT_EQ(r.frames, 1);
  EXPECT_EQ(r.distinct_frames, 1);
  EXPECT_EQ(r.objects, std::vector<std::string>{"box"});
  EXPECT_GT(r.templates, 0u);
  EXPECT_NE(r.frames_from.find("synthetic"), std::string::npos);
  const std::vector<std::string> stages = {"features",     "similarity", "clustering", "scoring",
                                           "nms",          "initial_pose", "first_fit", "mls",      "icp",
                                           "verification", "symmetries", "total"};
  ASSERT_EQ(r.stages.size(), stages.size());
  double sum = 0;
  for (std::size_t i = 0; i < stages.size(); ++i) {
    EXPECT_EQ(r.stages[i].stage, stages[i]);
    // MLS and ICP run in rounds over the candidates the first fit passed: none, no time.
    const bool idle = r.mean_refined == 0 && (stages[i] == "mls" || stages[i] == "icp");
    if (!idle) {
      EXPECT_GT(r.stages[i].median_ms, 0.0) << stages[i] << " took no time: not timed?";
    }
    EXPECT_DOUBLE_EQ(r.stages[i].median_ms, r.stages[i].p95_ms);  // one frame: one value
    if (i + 1 < stages.size()) sum += r.stages[i].median_ms;
  }
  EXPECT_GT(r.stages[0].median_ms, 0.0);
  EXPECT_GE(r.stages.back().median_ms, sum * 0.99);  // the total holds every stage
  EXPECT_NEAR(r.frames_per_s, 1000.0 / r.stages.back().median_ms, 1e-9);
  EXPECT_GT(r.opencv_match_ms, 0.0);
  EXPECT_NEAR(r.opencv_ratio, r.opencv_match_ms / r.vkpose_match_ms, 1e-9);
  EXPECT_GT(r.peak_rss_bytes, 0u);
  EXPECT_GT(r.gpu_peak_bytes, 0u);
  EXPECT_GE(r.gpu_peak_bytes, r.gpu_live_bytes);
  EXPECT_EQ(phases, (std::vector<std::string>{"loading banks", "detect", "cv::linemod"}));
  const auto j = bench::detectReportJson(r);
  for (const auto& s : stages) EXPECT_TRUE(j.at("stages").contains(s)) << s;
  EXPECT_TRUE(j.at("memory").contains("gpu_peak_bytes"));
  EXPECT_TRUE(j.contains("opencv"));
  // The kernel/host split: lavapipe writes timestamps, so the GPU stages have device time, no
  // more than the stage took; the CPU stages have none; host is the rest.
  for (const auto& s : r.stages) {
    EXPECT_GE(s.kernel_ms, 0.0) << s.stage;
    EXPECT_LE(s.kernel_ms, s.mean_ms * 1.01 + 0.01) << s.stage;
    EXPECT_NEAR(s.host_ms, s.mean_ms - s.kernel_ms, 1e-9) << s.stage;
    const bool gpu = s.stage == "features" || s.stage == "similarity" || s.stage == "total";
    if (gpu) {
      EXPECT_GT(s.kernel_ms, 0.0) << s.stage << ": no device time measured";
    }
    if (s.stage == "clustering" || s.stage == "mls" || s.stage == "icp") {
      EXPECT_EQ(s.kernel_ms, 0.0) << s.stage;
    }
    EXPECT_TRUE(j.at("stages").at(s.stage).contains("kernel_ms")) << s.stage;
    EXPECT_TRUE(j.at("stages").at(s.stage).contains("host_ms")) << s.stage;
  }
  // The pose stages' wall and CPU time and their threads.
  EXPECT_GT(r.pose_wall_ms, 0.0);
  EXPECT_GT(r.pose_cpu_ms, 0.0);
  // At most every core, at most one a candidate (none when the frame had no candidate).
  EXPECT_LE(r.pose_threads, std::max(1u, std::thread::hardware_concurrency()));
  if (r.mean_refined > 0) {
    EXPECT_GE(r.pose_threads, 1u);
  }
  EXPECT_EQ(j.at("pose_stages").at("threads").get<unsigned>(), r.pose_threads);
  EXPECT_NEAR(j.at("pose_stages").at("wall_to_cpu").get<double>(), r.pose_wall_ms / r.pose_cpu_ms, 1e-9);
}

TEST(BenchDetect, BadInputIsAnInputError) {
  bench::DetectBenchOptions o;
  EXPECT_NE(test::inputErrorOf([&] { bench::runDetectBenchmark(o, {}); }).find("--bank"), std::string::npos);
  o.banks = {"/nonexistent/bank.vkpb"};
  EXPECT_NE(test::inputErrorOf([&] { bench::runDetectBenchmark(o, {}); }).find("does not exist"), std::string::npos);
  o.frames = 0;
  EXPECT_NE(test::inputErrorOf([&] { bench::runDetectBenchmark(o, {}); }).find("--frames"), std::string::npos);
  EXPECT_THROW(bench::parseFrameSource("kinect"), InputError);
  EXPECT_EQ(bench::parseFrameSource("icbin"), bench::FrameSource::Icbin);
}

}  // namespace
}  // namespace vkpose

namespace vkpose {
namespace {

TEST(BenchDetect, SweepsOverObjectsAndInstancesGiveAPointEachAndAPlot) {
  const bench::DetectBenchOptions o = oneSyntheticFrame();
  const auto objects = bench::runDetectSweep(o, bench::DetectSweep::Objects, {1, 2}, {});
  ASSERT_EQ(objects.size(), 2u);
  EXPECT_EQ(objects[0].objects, 1);
  EXPECT_EQ(objects[1].objects, 2);
  EXPECT_EQ(objects[1].templates, 2 * objects[0].templates) << "the bank, twice";
  for (const auto& r : objects) {
    EXPECT_GT(r.total_ms, 0.0);
    EXPECT_GE(r.total_ms, 0.99 * (r.match_ms + r.pose_ms));
  }
  const auto instances = bench::runDetectSweep(o, bench::DetectSweep::Instances, {3}, {});
  ASSERT_EQ(instances.size(), 1u);
  EXPECT_EQ(instances[0].instances, 3);
  EXPECT_NE(instances[0].frames_from.find("3 instances"), std::string::npos) << instances[0].frames_from;
  const std::string table = bench::formatDetectSweep(objects, bench::DetectSweep::Objects);
  EXPECT_NE(table.find("objects"), std::string::npos);
  const std::string svg = bench::detectSweepSvg(objects, bench::DetectSweep::Objects);
  EXPECT_EQ(svg.rfind("<svg", 0), 0u);
  EXPECT_NE(svg.find("whole frame"), std::string::npos);
  EXPECT_EQ(bench::detectSweepJson(instances, bench::DetectSweep::Instances).at("points").size(), 1u);
  EXPECT_NE(test::inputErrorOf([&] { bench::runDetectSweep(o, bench::DetectSweep::Objects, {0}, {}); }).find("outside"),
            std::string::npos);
}

}  // namespace
}  // namespace vkpose
