// `vkpose eval --dataset DIR --bank OBJ_ID=BANK ...`: vkpose and the paper's baselines (LINEMOD
// alone, Drost et al.'s PPF) on the same images of a BOP dataset, scored with the paper's
// protocol; prints a table, writes a JSON report and BOP results CSVs.
#include <algorithm>
#include <filesystem>
#include <map>
#include <memory>
#include <optional>
#include <thread>

#include <fmt/core.h>
#include <nlohmann/json.hpp>

#include "cli/commands.hpp"
#include "cli/distributed_eval.hpp"
#include "util/progress.hpp"
#include "vkpose/detector.hpp"
#include "vkpose/error.hpp"
#include "vkpose/evaluation.hpp"
#include "vkpose/picking.hpp"
#include "vkpose/synth.hpp"

namespace vkpose::cli {

using util::ProgressBar;

namespace {
struct EvalOptions {
  std::string dataset, split = "test", out, report, config, pr_curve, sensor;
  std::vector<std::string> banks, methods;
  bool force = false;
  EvalRunParams params;
  DaskTarget dask;
  std::vector<std::string> grasps;  ///< grasp files: check each image's first pick against the truth
  PickParams pick;
  std::string pick_order = "combined";
};

/// The first picks of a run, checked against each image's ground truth.
struct PickCheck {
  int frames = 0, ok = 0;
  /// Images where not even the true instances could be taken (truthPickPlan: buried, out of
  /// reach, hemmed in, or less visible than --min-visib), and of those the ones left alone:
  /// no pick there is right.
  int nothing_to_pick = 0, left_alone = 0;
  std::vector<std::string> problems;  ///< "scene S image I: why"
};

/// The banks as a list in obj_id order (a detection's bank index) and obj_id -> that index,
/// shared by the callbacks that outlive this call.
std::pair<std::shared_ptr<std::vector<TemplateBank>>, std::shared_ptr<std::map<int, int>>> banksInObjIdOrder(
    const std::map<int, TemplateBank>& banks) {
  auto bank_list = std::make_shared<std::vector<TemplateBank>>();
  auto index = std::make_shared<std::map<int, int>>();
  for (const auto& [obj_id, bank] : banks) (*index)[obj_id] = static_cast<int>(bank_list->size()), bank_list->push_back(bank);
  return {bank_list, index};
}

/// An on_detections callback that plans each image's picks (its bin from SCENE/bin/IMAGE.json
/// when synth wrote one) and checks the first against the ground truth.
std::function<void(const BopImage&, const LinemodFrame&, const DetectionResult&)> pickChecker(
    const EvalOptions& opt, const std::map<int, TemplateBank>& banks, PickCheck& check) {
  const auto [bank_list, index] = banksInObjIdOrder(banks);
  auto grasps =
      std::make_shared<std::vector<std::vector<Grasp>>>(graspsForBanks(opt.grasps, *bank_list, opt.pick.symmetry_steps));
  const PickParams pick = opt.pick;
  const float min_visib = opt.params.eval.min_visib_fract;
  return [bank_list, index, grasps, pick, min_visib, &check](const BopImage& im, const LinemodFrame& frame,
                                                              const DetectionResult& result) {
    cv::Mat depth_m;
    frame.depth_mm.convertTo(depth_m, CV_32F, 0.001);
    const std::optional<BinBox> bin = loadSynthBin(im);
    Camera camera = im.camera;
    camera.width = frame.depth_mm.cols, camera.height = frame.depth_mm.rows;
    const PickPlan plan = planPicks(result.detections, *bank_list, *grasps, depth_m, camera, bin, pick);
    std::vector<TruthInstance> truth;
    for (const GroundTruthPose& g : im.gt)
      if (const auto it = index->find(g.obj_id); it != index->end())
        truth.push_back({it->second, {g.R, g.t}, g.visib_fract});
    std::string problem = firstPickProblem(plan, result.detections, *bank_list, truth, bin);
    const PickPlan possible = truthPickPlan(truth, *bank_list, *grasps, depth_m, camera, bin, pick, min_visib);
    ++check.frames;
    if (possible.picks.empty()) ++check.nothing_to_pick;
    if (possible.picks.empty() && problem == "no pick") {
      ++check.left_alone;
      problem.clear();
    } else if (problem == "no pick") {
      const Pick& p = possible.picks.front();
      problem = fmt::format("no pick, where true instance {} ({:.0f} % visible) could be taken by grasp '{}'",
                            p.detection, 100.f * truth[static_cast<std::size_t>(p.detection)].visib_fract, p.grasp.name);
    }
    if (problem.empty()) ++check.ok;
    else check.problems.push_back(fmt::format("scene {} image {}: {}", im.scene_id, im.image_id, problem));
  };
}

/// Scaled copies of the parts (synth --scaled-copies) that a detection reported as the part.
struct CopyCheck {
  int copies = 0, reported = 0;
  /// The copies of objects given a bank: a copy of an object without one (a part training
  /// refused as too small) can never be reported, so these are the ones that tell.
  int banked_copies = 0;
};

/// An on_detections callback that counts the scaled copies of each image (SCENE/scaled/IMAGE.json
/// when synth wrote one) reported as the part at score 0.5 or more, then calls `next`.
std::function<void(const BopImage&, const LinemodFrame&, const DetectionResult&)> copyChecker(
    const std::map<int, TemplateBank>& banks, CopyCheck& check,
    std::function<void(const BopImage&, const LinemodFrame&, const DetectionResult&)> next) {
  const auto [bank_list, index] = banksInObjIdOrder(banks);
  return [bank_list, index, &check, next](const BopImage& im, const LinemodFrame& frame, const DetectionResult& result) {
    const std::vector<ScaledCopy> copies = loadScaledCopies(im);
    check.copies += static_cast<int>(copies.size());
    check.banked_copies += static_cast<int>(
        std::count_if(copies.begin(), copies.end(), [&](const ScaledCopy& c) { return index->contains(c.obj_id); }));
    check.reported += scaledCopiesReported(copies, result.detections, *bank_list, *index, 0.5f);
    if (next) next(im, frame, result);
  };
}

/// "OBJ_ID=BANK" pairs -> obj_id -> bank path.
std::map<int, std::string> parseBankArgs(const std::vector<std::string>& args) {
  std::map<int, std::string> out;
  for (const auto& a : args) {
    const auto eq = a.find('=');
    int id = -1;
    try {
      std::size_t used = 0;
      if (eq != std::string::npos) id = std::stoi(a.substr(0, eq), &used);
      if (used != eq) id = -1;
    } catch (const std::exception&) {
      id = -1;
    }
    if (id < 0 || eq + 1 >= a.size())
      throw InputError(fmt::format("--bank {}: expected OBJ_ID=BANK, e.g. --bank 5=can.vkpb (OBJ_ID: the BOP "
                                   "object id)",
                                   a));
    if (!out.emplace(id, a.substr(eq + 1)).second) throw InputError(fmt::format("--bank: object {} given twice", id));
  }
  return out;
}

/// Nothing is computed before every output is known to be writable.
void checkOutputs(const EvalOptions& opt, const std::vector<EvalMethod>& methods) {
  std::vector<std::string> outputs;
  if (!opt.report.empty()) outputs.push_back(opt.report);
  if (!opt.pr_curve.empty()) outputs.push_back(opt.pr_curve);
  if (!opt.out.empty())
    for (EvalMethod m : methods) outputs.push_back(methodResultsPath(opt.out, m));
  for (const auto& path : outputs) {
    if (!opt.force && std::filesystem::exists(path))
      throw InputError(path + " exists: pass --force to overwrite it");
    const auto folder = std::filesystem::path(path).parent_path();
    if (!folder.empty() && !std::filesystem::is_directory(folder))
      throw InputError(fmt::format("{}: no such folder to write {} into", folder.string(), path));
  }
}

/// Per method: precision and recall at score 0.5, and the best F1 with its threshold.
void printPrSummary(const EvalReport& report) {
  for (const MethodEvaluation& m : report.methods) {
    const auto curve = precisionRecallCurve(m.outcomes, m.summary.total.tp + m.summary.total.fn);
    const PrPoint* at_half = nullptr;
    const PrPoint* best = nullptr;
    for (const PrPoint& pt : curve) {
      if (pt.threshold >= 0.5f) at_half = &pt;
      if (!best || pt.scores.f1 > best->scores.f1) best = &pt;
    }
    if (!best) continue;
    fmt::print("{}: {}best F1 {:.3f} at score >= {:.3g}\n", methodName(m.method),
               at_half ? fmt::format("score >= 0.5: precision {:.3f}, recall {:.3f}; ", at_half->scores.precision,
                                     at_half->scores.recall)
                       : std::string("no estimate scores 0.5; "),
               best->scores.f1, best->threshold);
  }
}

/// The report of the run: on this process, or spread over Dask's workers.
EvalReport evaluate(const EvalOptions& opt, const GlobalOptions& global, const EvalRunParams& params, PickCheck& picks,
                    CopyCheck& copies) {
  const BopDataset dataset = loadBopDataset(opt.dataset, opt.split);
  const std::map<int, std::string> bank_paths = parseBankArgs(opt.banks);
  if (opt.dask.workers > 0 || !opt.dask.scheduler.empty()) {
    if (!opt.grasps.empty()) throw InputError("--grasps checks the picks in this process: leave out --workers/--dask");
    EvalJob job;
    job.dataset = std::filesystem::absolute(opt.dataset).string();
    job.split = opt.split;
    job.params = params;
    // Every worker reads the banks itself; on this machine's cluster the cores are shared out.
    for (const auto& [obj_id, path] : bank_paths) {
      if (!std::filesystem::is_regular_file(path)) throw InputError(path + ": no such bank file");
      job.banks[obj_id] = std::filesystem::absolute(path).string();
    }
    if (job.params.detector.threads == 0 && opt.dask.workers > 0)
      job.params.detector.threads = std::max(1u, std::thread::hardware_concurrency() / static_cast<unsigned>(opt.dask.workers));
    return runOnDask(job, opt.dask, global.quiet);
  }
  std::map<int, TemplateBank> banks;
  for (const auto& [obj_id, path] : bank_paths) banks.emplace(obj_id, loadBank(path));
  checkBanksAgainstDataset(banks, dataset);
  EvalRunParams run = params;
  if (!opt.grasps.empty()) run.on_detections = pickChecker(opt, banks, picks);
  run.on_detections = copyChecker(banks, copies, run.on_detections);
  GpuContext ctx(global.gpu());
  ProgressBar bar("evaluating", global.quiet);
  EvalReport report =
      runEvaluation(ctx, dataset, banks, run, [&](std::size_t done, std::size_t total) { bar.update(done, total); });
  bar.finish();
  return report;
}

/// `vkpose eval`.
ExitCode runEval(const EvalOptions& opt, const GlobalOptions& global) {
  EvalRunParams params = opt.params;
  params.detector = withConfig(opt.config, params.detector);
  if (!opt.sensor.empty()) params.detector.sensor = sensorProfile(opt.sensor);
  params.linemod.match = params.detector.match;
  if (!opt.methods.empty()) {
    params.methods.clear();
    for (const auto& m : opt.methods) params.methods.push_back(parseEvalMethod(m));
  } else if (params.no_depth) {
    params.methods = {EvalMethod::Vkpose};  // the baselines need depth
  }
  if (params.no_depth && !opt.grasps.empty()) throw InputError("--grasps needs depth (not --no-depth)");
  checkOutputs(opt, params.methods);
  if (!std::filesystem::is_directory(opt.dataset))
    throw InputError(opt.dataset + ": no such dataset folder");

  PickCheck picks;
  CopyCheck copies;
  const EvalReport report = evaluate(opt, global, params, picks, copies);
  for (const auto& w : report.warnings) fmt::print(stderr, "vkpose: warning: {}\n", w);

  const std::string criterion = params.eval.error == PoseErrorType::Proj2D
                                    ? fmt::format("proj2d under {:.1f} px", params.eval.proj2d_px)
                                    : fmt::format("k_m {:.2f}", params.eval.k_m);
  fmt::print("{} image{} of {} ({}{}), {} object{}, {}, on {}\n", report.images, report.images == 1 ? "" : "s",
             report.dataset, report.split, params.no_depth ? ", without depth" : "", report.objects.size(),
             report.objects.size() == 1 ? "" : "s", criterion, report.device);
  fmt::print("{}", evalReportTable(report));
  if (!opt.grasps.empty()) {
    fmt::print("first pick ({}): right in {} of {} images ({:.1f} %): {} right and clear, {} with nothing a gripper "
               "could take left alone\n",
               opt.pick_order, picks.ok, picks.frames, picks.frames > 0 ? 100.0 * picks.ok / picks.frames : 0.0,
               picks.ok - picks.left_alone, picks.left_alone);
    if (picks.nothing_to_pick > 0)
      fmt::print("  ({} image{} had nothing a gripper could take, even at the true poses{})\n", picks.nothing_to_pick,
                 picks.nothing_to_pick == 1 ? "" : "s",
                 params.eval.min_visib_fract > 0.f
                     ? fmt::format(", of instances at least {:.0f} % visible", 100.f * params.eval.min_visib_fract)
                     : "");
    for (const std::string& p : picks.problems) fmt::print("  {}\n", p);
  }
  if (copies.copies > 0)
    fmt::print("scaled copies (0.8-0.9x, 1.1-1.2x) reported as the part at score >= 0.5: {} of {} ({:.1f} %){}\n",
               copies.reported, copies.copies, 100.0 * copies.reported / copies.copies,
               copies.banked_copies < copies.copies
                   ? fmt::format("; of the objects given a bank, {} of {} ({:.1f} %)", copies.reported,
                                 copies.banked_copies,
                                 copies.banked_copies > 0 ? 100.0 * copies.reported / copies.banked_copies : 0.0)
                   : "");
  if (!opt.report.empty()) {
    std::string json = evalReportJson(report);
    if (!opt.grasps.empty() || copies.copies > 0) {
      nlohmann::json doc = nlohmann::json::parse(json);
      if (!opt.grasps.empty())
        doc["picks"] = {{"order", opt.pick_order}, {"images", picks.frames}, {"first_pick_ok", picks.ok},
                        {"nothing_to_pick", picks.nothing_to_pick}, {"left_alone", picks.left_alone},
                        {"problems", picks.problems}};
      if (copies.copies > 0)
        doc["scaled_copies"] = {{"copies", copies.copies},
                                {"copies_of_objects_with_a_bank", copies.banked_copies},
                                {"reported", copies.reported}};
      json = doc.dump(2) + "\n";
    }
    writeTextFile(opt.report, json, opt.force);
    if (!global.quiet) fmt::print("wrote {}\n", opt.report);
  }
  if (!opt.pr_curve.empty()) {
    const bool svg = std::filesystem::path(opt.pr_curve).extension() == ".svg";
    writeTextFile(opt.pr_curve, svg ? precisionRecallSvg(report) : precisionRecallCsv(report), opt.force);
    printPrSummary(report);
    if (!global.quiet) fmt::print("wrote {}\n", opt.pr_curve);
  }
  if (!opt.out.empty())
    for (const MethodEvaluation& m : report.methods) {
      const std::string path = methodResultsPath(opt.out, m.method);
      saveBopResults(path, m.results);
      if (!global.quiet) fmt::print("wrote {} ({} estimates)\n", path, m.results.size());
    }
  // Unreadable images do not stop a long run, but a script must notice them.
  for (const SkippedImage& s : report.skipped)
    fmt::print(stderr, "vkpose: error: scene {} image {} skipped: {}\n", s.scene_id, s.image_id, s.reason);
  return report.skipped.empty() ? kOk : kBadInput;
}

}  // namespace

namespace {

/// `--workers`, `--dask` and their settings.
void addSpreadOptions(CLI::App* sub, EvalOptions& o) {
  auto* opt = &o;
  auto* spread = "Spread over Dask's workers (python3-distributed; docs/evaluation.md)";
  auto* workers = sub->add_option("--workers", opt->dask.workers,
                                  "Run the images on N worker processes of a Dask cluster on this machine")
                      ->check(CLI::Range(1, 1024))
                      ->group(spread);
  sub->add_option("--dask", opt->dask.scheduler,
                  "Run the images on the workers of the Dask scheduler at ADDRESS (tcp://host:8786); the dataset and "
                  "banks must be at the same paths on every worker")
      ->excludes(workers)
      ->group(spread);
  sub->add_option("--connect-timeout", opt->dask.connect_timeout_s, "Seconds to wait for the --dask scheduler")
      ->check(CLI::Range(1, 3600))
      ->capture_default_str()
      ->group(spread);
  sub->add_option("--batch", opt->dask.batch, "Images per Dask task (0: about 4 tasks a worker)")
      ->check(CLI::Range(0, 100000))
      ->group(spread);
}

/// `--grasps` and how picks are ordered and checked.
void addPickingOptions(CLI::App* sub, EvalOptions& o) {
  auto* opt = &o;
  auto* picking = "Bin picking (docs/picking.md)";
  auto* grasps = sub->add_option("--grasps", opt->grasps,
                                 "Grasp file of an object: plan each image's picks (the bin from SCENE/bin/IMAGE.json "
                                 "when synth wrote it) and check the first against the ground truth; repeat for "
                                 "several objects")
                     ->group(picking);
  addPickFlags(sub, grasps, opt->pick_order, opt->pick, picking);
}

/// What counts as a correct estimate, and which instances count.
void addProtocolOptions(CLI::App* sub, EvalRunParams& p) {
  auto* protocol = "Evaluation protocol";
  sub->add_option("--k-m", p.eval.k_m, "An estimate is correct when its ADD/ADI is below k_m times the diameter")
      ->check(CLI::Range(0.001, 10.0))
      ->capture_default_str()
      ->group(protocol);
  const std::map<std::string, PoseErrorType> metrics{{"auto", PoseErrorType::Auto},
                                                     {"add", PoseErrorType::ADD},
                                                     {"adi", PoseErrorType::ADI},
                                                     {"proj2d", PoseErrorType::Proj2D}};
  sub->add_option("--metric", p.eval.error,
                  "Pose error: auto (ADI for symmetric objects, ADD otherwise), add, adi, or proj2d (mean 2D "
                  "projection error of the model points, correct under --proj2d-px; the usual colour-only score)")
      ->transform(CLI::CheckedTransformer(metrics, CLI::ignore_case))
      ->default_str("auto")
      ->group(protocol);
  sub->add_option("--proj2d-px", p.eval.proj2d_px, "With --metric proj2d: an estimate is correct under this many pixels")
      ->check(CLI::Range(0.1, 1000.0))
      ->capture_default_str()
      ->group(protocol);
  sub->add_flag("--no-depth", p.no_depth,
                "Ignore the dataset's depth images: vkpose detects colour-only (the baselines need depth)")
      ->group(protocol);
  sub->add_option("--min-visib", p.eval.min_visib_fract,
                  "Instances less visible than this (visib_fract) are neither missed nor found")
      ->check(CLI::Range(0.0, 1.0))
      ->capture_default_str()
      ->group(protocol);
}

/// The methods' own parameters.
void addMethodOptions(CLI::App* sub, EvalRunParams& p) {
  auto* methods = "Method parameters";
  addParamFlag(sub, p.detector, "--threshold", ", vkpose and linemod")->group(methods);
  sub->add_option("--linemod-max-per-object", p.linemod.max_per_object,
                  "linemod: detections kept per object and image, the best by similarity (0: every raw match)")
      ->check(CLI::Range(0, 100000000))
      ->capture_default_str()
      ->group(methods);
  sub->add_option("--ppf-poses", p.ppf.max_poses, "ppf: poses reported per object and image")
      ->check(CLI::Range(1, 1000))
      ->capture_default_str()
      ->group(methods);
  sub->add_option("--ppf-model-step", p.ppf.model_step,
                  "ppf: model sampling step, fraction of the diameter (finer trains much slower)")
      ->check(CLI::Range(0.02, 0.5))
      ->capture_default_str()
      ->group(methods);
  sub->add_option("--ppf-scene-step", p.ppf.scene_step, "ppf: scene sampling step, fraction of the diameter")
      ->check(CLI::Range(0.02, 1.0))
      ->capture_default_str()
      ->group(methods);
}

}  // namespace

Runner addEvalCommand(CLI::App& app, const GlobalOptions& global) {
  auto opt = std::make_shared<EvalOptions>();
  auto& p = opt->params;
  auto* sub = app.add_subcommand(
      "eval", "Score vkpose and the paper's baselines (linemod, ppf) side by side on a BOP dataset");
  sub->add_option("--dataset", opt->dataset, "BOP dataset folder (camera.json, models/, SPLIT/SCENE/...)")->required();
  sub->add_option("--split", opt->split, "Split folder of the dataset")->capture_default_str();
  sub->add_option("--bank", opt->banks,
                  "OBJ_ID=BANK: the template bank (.vkpb) of BOP object OBJ_ID; repeat for several objects. The "
                  "evaluated objects are these");
  sub->add_option("--method", opt->methods, "Method to run: vkpose, linemod or ppf; repeat (default: all three)");
  sub->add_option("--out", opt->out,
                  "BOP results CSV, one per method: METHOD_ is put before the file name (--out r/lmo-test.csv writes "
                  "r/vkpose_lmo-test.csv, ...)");
  sub->add_option("--report", opt->report, "JSON report to write (per method: average and per-object scores)");
  sub->add_option("--pr-curve", opt->pr_curve,
                  "Precision-recall curves to write (per method, all objects and each object: precision, recall "
                  "and F1 of the estimates scoring at least each threshold): CSV, or an SVG plot when FILE ends in .svg");
  sub->add_option("--images", p.max_images, "Evaluate the first N images only (0: all)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  sub->add_flag("--force", opt->force, "Overwrite --out and --report files that exist");
  addParamFlag(sub, p.detector, "--threads", "; with --workers, the cores shared out among the workers");
  addSpreadOptions(sub, *opt);
  addConfigOption(sub, opt->config);
  addSensorOption(sub, opt->sensor,
                  "its noise sets the lengths that follow each object (vkpose config --explain); with close-range, "
                  "parts under 10 cm are also matched on colour alone (their depth is unreliable)");
  addPickingOptions(sub, *opt);
  addProtocolOptions(sub, p);
  addMethodOptions(sub, p);
  return [opt, &global]() {
    opt->pick.order = parsePickOrder(opt->pick_order);
    return runEval(*opt, global);
  };
}

}  // namespace vkpose::cli
