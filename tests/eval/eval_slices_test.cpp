// A run in slices, as `vkpose eval --workers` gives Dask's workers: the slices' reports,
// carried as text, merge into the report of one run; a job carried as text is the same job;
// an unreadable image is skipped and named while the run goes on. Data of its own (a small
// synthetic dataset of the L-shaped part): no ../shared needed.
#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "mesh_support.hpp"
#include "test_support.hpp"
#include "vkpose/error.hpp"
#include "vkpose/evaluation.hpp"
#include "vkpose/synth.hpp"
#include "vkpose/bank.hpp"

namespace vkpose {
namespace {
namespace fs = std::filesystem;

constexpr int kImages = 4;

/// Four 320x240 images of the L-shaped part (2-3 instances each, clutter), written once.
const std::string& slicesDataset() {
  static const std::string dir = [] {
    const fs::path d = test::scratchDir("vkpose_eval_slices_");
    fs::remove_all(d);
    fs::create_directories(d / "meshes");
    const std::string ply = (d / "meshes" / "l_part.ply").string();
    writePlyMillimetres(test::lShapeMesh(), ply, true);
    SynthParams p;
    p.meshes = {ply};
    p.units = MeshUnits::Millimetres;
    p.images = kImages;
    p.seed = 11;
    p.min_instances = 2;
    p.max_instances = 3;
    p.clutter = 2;
    p.camera.width = 320;
    p.camera.height = 240;
    p.camera.cx = 159.5;
    p.camera.cy = 119.5;
    p.camera.fx = p.camera.fy = 286.0;
    generateSyntheticDataset(test::context(), p, (d / "set").string(), false);
    return (d / "set").string();
  }();
  return dir;
}

/// A coarse bank of the part for the dataset's camera.
const TemplateBank& lPartBank() {
  static const TemplateBank bank = [] {
    TrainingParams params;
    params.views.viewpoints = 30;
    params.views.radii = {0.6f, 1.2f, 0.3f};
    params.views.inplane_deg = {-30.f, 30.f, 30.f};
    params.camera = loadBopDataset(slicesDataset()).camera;
    return test::cachedBank(test::lShapeMesh(), params);
  }();
  return bank;
}

EvalRunParams slicesParams() {
  EvalRunParams p;
  // LINEMOD alone reports every match: many estimates, so the merge has plenty to get wrong.
  p.methods = {EvalMethod::Vkpose, EvalMethod::Linemod};
  return p;
}

/// The report JSON without the times, which differ from run to run.
nlohmann::json withoutTimes(const EvalReport& r) {
  auto doc = nlohmann::json::parse(evalReportJson(r));
  for (auto& [name, m] : doc.at("methods").items()) {
    m.at("average").erase("ms_per_image");
    for (auto& [id, o] : m.at("objects").items()) o.erase("ms_per_image");
  }
  return doc;
}

void expectSameEstimates(const MethodEvaluation& a, const MethodEvaluation& b) {
  ASSERT_EQ(a.results.size(), b.results.size()) << methodName(a.method);
  for (std::size_t i = 0; i < a.results.size(); ++i) {
    const BopResult &x = a.results[i], &y = b.results[i];
    EXPECT_EQ(x.scene_id, y.scene_id);
    EXPECT_EQ(x.im_id, y.im_id);
    EXPECT_EQ(x.estimate.obj_id, y.estimate.obj_id);
    EXPECT_EQ(x.estimate.score, y.estimate.score);  // bit for bit: floats travel exactly
    EXPECT_TRUE(x.estimate.R == y.estimate.R && x.estimate.t == y.estimate.t) << methodName(a.method) << " #" << i;
  }
  ASSERT_EQ(a.outcomes.size(), b.outcomes.size());
  for (std::size_t i = 0; i < a.outcomes.size(); ++i) {
    EXPECT_EQ(a.outcomes[i].score, b.outcomes[i].score);
    EXPECT_EQ(a.outcomes[i].correct, b.outcomes[i].correct);
  }
}

TEST(EvalSlices, SlicesCarriedAsTextMergeIntoTheReportOfOneRun) {
  const BopDataset dataset = loadBopDataset(slicesDataset());
  ASSERT_EQ(dataset.images.size(), static_cast<std::size_t>(kImages));
  Evaluator evaluator(test::context(), dataset, {{1, lPartBank()}}, slicesParams());
  EXPECT_EQ(evaluator.imageRange(), std::make_pair(std::size_t{0}, std::size_t{kImages}));
  const EvalReport whole = evaluator.run(0, kImages);
  ASSERT_EQ(whole.methods.size(), 2u);
  EXPECT_GT(whole.methods[1].results.size(), 10u);  // linemod's matches: the merge has work to do
  EXPECT_GT(whole.methods[0].results.size(), 0u) << "vkpose found nothing: the test compares nothing";

  std::vector<EvalReport> parts;
  for (auto [first, count] : {std::pair{0, 1}, std::pair{1, 2}, std::pair{3, 1}})
    parts.push_back(parseEvalReportState(evalReportState(evaluator.run(first, count))));
  const EvalReport merged = mergeEvalReports(parts);
  EXPECT_EQ(merged.images, kImages);
  EXPECT_EQ(withoutTimes(merged), withoutTimes(whole));
  for (std::size_t m = 0; m < whole.methods.size(); ++m) expectSameEstimates(merged.methods[m], whole.methods[m]);
  EXPECT_EQ(precisionRecallCsv(merged), precisionRecallCsv(whole));
  // Times: the merged average is the image-weighted mean of the parts'.
  double expected = 0;
  for (const EvalReport& p : parts) expected += p.methods[0].ms_per_image * p.images / kImages;
  EXPECT_NEAR(merged.methods[0].ms_per_image, expected, 1e-9);

  // A slice outside the run, and reports of another run, are refused.
  test::expectInputError([&] { evaluator.run(3, 2); }, {"images 3 to 5"});
  EvalReport other = parts[0];
  other.split = "val";
  test::expectInputError([&] { mergeEvalReports({parts[0], other}); }, {"different runs"});
  test::expectInputError([&] { mergeEvalReports({}); }, {"no reports"});
  test::expectInputError([] { parseEvalReportState("{\"vkpose_report_state\": 1}"); }, {"cannot be read"});
}

TEST(EvalSlices, AJobCarriedAsTextIsTheSameJob) {
  EvalJob job;
  job.dataset = "/data/lmo";
  job.split = "val";
  job.banks = {{5, "/banks/can.vkpb"}, {8, "/banks/driller.vkpb"}};
  job.params.methods = {EvalMethod::Ppf, EvalMethod::Vkpose};
  job.params.first_image = 3;
  job.params.max_images = 7;
  job.params.detector.threads = 1;
  job.params.detector.match.threshold = 83.5f;
  job.params.ppf.model_step = 0.07f;
  job.params.ppf.icp_poses = 4;
  job.params.linemod.max_per_object = 12;
  job.params.eval.k_m = 0.1f;
  job.params.eval.error = PoseErrorType::ADI;
  job.params.eval.min_visib_fract = 0.25f;
  const std::string text = evalJobJson(job);
  const EvalJob back = parseEvalJob(text);
  EXPECT_EQ(evalJobJson(back), text);
  EXPECT_EQ(back.banks, job.banks);
  EXPECT_EQ(back.params.methods, job.params.methods);
  EXPECT_EQ(back.params.detector.match.threshold, 83.5f);
  EXPECT_EQ(back.params.linemod.match.threshold, 83.5f);  // linemod matches as the detector does
  EXPECT_EQ(back.params.ppf.model_step, 0.07f);
  EXPECT_EQ(back.params.eval.error, PoseErrorType::ADI);

  test::expectInputError([] { parseEvalJob("[]"); }, {"evaluation job"});
  auto doc = nlohmann::json::parse(text);
  doc["methods"] = {"magic"};
  test::expectInputError([&] { parseEvalJob(doc.dump()); }, {"unknown method 'magic'"});
  doc = nlohmann::json::parse(text);
  doc["detector"]["match"]["threshold"] = 150;
  test::expectInputError([&] { parseEvalJob(doc.dump()); }, {"threshold"});
  doc = nlohmann::json::parse(text);
  doc["banks"] = {{"five", "/banks/can.vkpb"}};
  test::expectInputError([&] { parseEvalJob(doc.dump()); }, {"cannot be read"});
}

TEST(EvalSlices, AnUnreadableImageIsSkippedAndNamedAndTheRunGoesOn) {
  // A copy of the dataset whose second image's colour file is cut short.
  const fs::path copy = fs::path(slicesDataset()).parent_path() / "broken";
  fs::remove_all(copy);
  fs::copy(slicesDataset(), copy, fs::copy_options::recursive);
  const BopDataset dataset = loadBopDataset(copy.string());
  const BopImage& bad = dataset.images[1];
  fs::resize_file(bad.rgb_path, fs::file_size(bad.rgb_path) / 3);

  EvalRunParams params = slicesParams();
  params.methods = {EvalMethod::Linemod};
  std::size_t steps = 0;
  const EvalReport r = runEvaluation(test::context(), dataset, {{1, lPartBank()}}, params,
                                     [&](std::size_t done, std::size_t) { steps = done; });
  EXPECT_EQ(steps, static_cast<std::size_t>(kImages));
  EXPECT_EQ(r.images, kImages - 1);
  ASSERT_EQ(r.skipped.size(), 1u);
  EXPECT_EQ(r.skipped[0].scene_id, bad.scene_id);
  EXPECT_EQ(r.skipped[0].image_id, bad.image_id);
  EXPECT_NE(r.skipped[0].reason.find(fs::path(bad.rgb_path).filename().string()), std::string::npos) << r.skipped[0].reason;
  for (const BopResult& b : r.methods[0].results) EXPECT_NE(b.im_id, bad.image_id);
  const auto doc = nlohmann::json::parse(evalReportJson(r));
  EXPECT_EQ(doc.at("skipped").at(0).at("image_id").get<int>(), bad.image_id);
  fs::remove_all(copy);
}

}  // namespace
}  // namespace vkpose
