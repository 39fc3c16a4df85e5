// Methods side by side on a BOP dataset: run, time, score, report.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <optional>
#include <set>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "eval/baselines.hpp"
#include "hypotheses/cluster_score.hpp"
#include "util/timing.hpp"
#include "vkpose/bank.hpp"
#include "vkpose/detector.hpp"
#include "vkpose/device.hpp"
#include "vkpose/error.hpp"
#include "vkpose/evaluation.hpp"
#include "vkpose/frame.hpp"
#include "vkpose/geometry.hpp"

namespace vkpose {

namespace {
using util::msSince;

PoseEstimate estimateOf(int obj_id, float score, const Pose& pose) { return {obj_id, score, pose.R, pose.t}; }

/// One method's state over the run: the estimator and what it has counted so far.
struct MethodRun {
  EvalMethod method;
  std::map<int, EvalCounts> counts;
  double total_ms = 0;
  std::map<int, double> object_ms;
  std::vector<BopResult> results;
  std::vector<ScoredOutcome> outcomes;
  std::map<int, VisibilityRecall> by_visibility;
};

/// The visibility bins of all objects together.
VisibilityRecall allObjects(const std::map<int, VisibilityRecall>& by_object) {
  VisibilityRecall sum;
  for (const auto& [obj_id, v] : by_object) sum += v;
  return sum;
}

/// "40-60 %" for bin 2.
std::string visibilityBinName(int bin) {
  constexpr int step = 100 / VisibilityRecall::kBins;
  return fmt::format("{}-{} %", bin * step, (bin + 1) * step);
}
}  // namespace

std::string methodName(EvalMethod method) {
  switch (method) {
    case EvalMethod::Vkpose: return "vkpose";
    case EvalMethod::Linemod: return "linemod";
    case EvalMethod::Ppf: return "ppf";
  }
  return "?";
}

EvalMethod parseEvalMethod(const std::string& name) {
  for (EvalMethod m : {EvalMethod::Vkpose, EvalMethod::Linemod, EvalMethod::Ppf})
    if (methodName(m) == name) return m;
  throw InputError(fmt::format("unknown method '{}': the methods are vkpose, linemod and ppf", name));
}

std::string methodResultsPath(const std::string& path, EvalMethod method) {
  const std::filesystem::path p(path);
  return (p.parent_path() / (methodName(method) + "_" + p.filename().string())).string();
}

void checkBanksAgainstDataset(const std::map<int, TemplateBank>& banks, const BopDataset& dataset) {
  for (const auto& [obj_id, bank] : banks) {
    const auto it = dataset.models.find(obj_id);
    if (it == dataset.models.end()) {
      std::string known;
      for (const auto& [id, info] : dataset.models) known += (known.empty() ? "" : ", ") + std::to_string(id);
      throw InputError(fmt::format("bank '{}' is for object {}, which {} does not have (its objects: {})", bank.object,
                                   obj_id, dataset.root, known));
    }
    const float d = it->second.diameter;
    if (std::abs(bank.diameter / d - 1.f) > 0.1f)
      throw InputError(fmt::format(
          "bank '{}' was trained on a mesh {:.4f} m across, but object {} of the dataset is {:.4f} m across: a bank "
          "of another object, or a mesh read in the wrong units (vkpose train --units)",
          bank.object, bank.diameter, obj_id, d));
  }
}

std::vector<std::string> distanceCoverageWarnings(const std::map<int, TemplateBank>& banks, const BopDataset& dataset,
                                                  std::size_t first, std::size_t end, float min_visib) {
  std::vector<std::string> out;
  end = std::min(end, dataset.images.size());
  for (const auto& [obj_id, bank] : banks) {
    const auto [lo, hi] = coveredDistances(bank.params.views.radii);
    int instances = 0, nearer = 0, farther = 0;
    float nearest = 1e9f, farthest = 0.f;
    for (std::size_t i = first; i < end; ++i) {
      const BopImage& im = dataset.images[i];
      for (const GroundTruthPose& gt : im.gt) {
        if (gt.obj_id != obj_id || gt.visib_fract < min_visib) continue;  // loadBopDataset copies gt_info's
        ++instances;
        const float d = (gt.R * bank.centre + gt.t).norm();
        if (d < lo) ++nearer, nearest = std::min(nearest, d);
        if (d > hi) ++farther, farthest = std::max(farthest, d);
      }
    }
    if (nearer + farther == 0) continue;
    std::string where;
    if (nearer) where = fmt::format("{} nearer (down to {:.2f} m)", nearer, nearest);
    if (farther) where += fmt::format("{}{} farther (up to {:.2f} m)", where.empty() ? "" : ", ", farther, farthest);
    out.push_back(fmt::format(
        "{} of {} instances of object {} lie outside the distances its bank '{}' was trained at ({:.2f}-{:.2f} m "
        "from --radii {:g}:{:g}:{:g}): {}; LINEMOD misses most of those, so train with --radii covering the "
        "scenes' distances",
        nearer + farther, instances, obj_id, bank.object, lo, hi, bank.params.views.radii.from,
        bank.params.views.radii.to, bank.params.views.radii.step, where));
  }
  return out;
}

struct Evaluator::State {
  State(GpuContext& c, BopDataset d, const EvalRunParams& p) : ctx(c), dataset(std::move(d)), params(p) {}
  GpuContext& ctx;
  BopDataset dataset;
  EvalRunParams params;
  std::vector<int> objects;  ///< the evaluated obj_ids, ascending; bank index b is objects[b]
  std::map<int, EvalModel> models;
  std::optional<Detector> detector;
  std::optional<LinemodBaseline> linemod;
  std::optional<PpfBaseline> ppf;
};

Evaluator::Evaluator(GpuContext& ctx, BopDataset dataset, const std::map<int, TemplateBank>& banks,
                     const EvalRunParams& params) {
  if (params.methods.empty()) throw InputError("no method to evaluate");
  const std::set<EvalMethod> unique(params.methods.begin(), params.methods.end());
  if (unique.size() != params.methods.size()) throw InputError("a method is asked for twice");
  if (params.no_depth)
    for (EvalMethod m : params.methods)
      if (m != EvalMethod::Vkpose)
        throw InputError(fmt::format("the {} baseline needs depth: without depth evaluate vkpose alone (--method vkpose)",
                                     methodName(m)));
  const bool needs_banks = unique.count(EvalMethod::Vkpose) || unique.count(EvalMethod::Linemod);
  if (needs_banks && banks.empty())
    throw InputError("vkpose and linemod need a template bank per object: --bank OBJ_ID=BANK");
  if (params.max_images < 0) throw InputError("the number of images must be >= 0");
  if (params.first_image < 0) throw InputError("the first image must be >= 0");
  checkBanksAgainstDataset(banks, dataset);
  if (dataset.images.empty()) throw InputError(fmt::format("{} has no annotated {} images", dataset.root, dataset.split));
  if (static_cast<std::size_t>(params.first_image) >= dataset.images.size())
    throw InputError(fmt::format("{} has {} annotated {} images: none from image {} on", dataset.root,
                                 dataset.images.size(), dataset.split, params.first_image));

  state_ = std::make_unique<State>(ctx, std::move(dataset), params);
  State& s = *state_;
  for (const auto& [obj_id, bank] : banks) s.objects.push_back(obj_id);
  if (banks.empty())
    for (const auto& [obj_id, info] : s.dataset.models) s.objects.push_back(obj_id);
  const std::set<int> evaluated(s.objects.begin(), s.objects.end());
  s.models = loadEvalModels(s.dataset);
  std::erase_if(s.models, [&](const auto& m) { return !evaluated.count(m.first); });

  std::vector<TemplateBank> bank_list;  // in obj_id order
  for (const auto& [obj_id, bank] : banks) bank_list.push_back(bank);
  if (unique.count(EvalMethod::Vkpose)) s.detector.emplace(ctx, bank_list, params.detector);
  if (unique.count(EvalMethod::Linemod)) s.linemod.emplace(ctx, bank_list, params.linemod);
  if (unique.count(EvalMethod::Ppf)) {
    s.ppf.emplace(params.ppf);
    for (int obj_id : s.objects)
      s.ppf->addObject(obj_id, loadMesh(s.dataset.modelPath(obj_id), MeshUnits::Millimetres));
  }
}

Evaluator::~Evaluator() = default;

std::pair<std::size_t, std::size_t> Evaluator::imageRange() const {
  const std::size_t n = state_->dataset.images.size();
  const auto first = static_cast<std::size_t>(state_->params.first_image);
  const auto max = static_cast<std::size_t>(state_->params.max_images);
  return {first, max > 0 ? std::min(n, first + max) : n};
}

namespace {
/// One method's estimates on one image, and the time they took (template upload left out).
std::vector<PoseEstimate> estimatesOf(Evaluator::State& s, MethodRun& run, const BopImage& im,
                                      const LinemodFrame& frame, double& image_ms, std::set<std::string>& warnings) {
  std::vector<PoseEstimate> estimates;
  const auto t0 = std::chrono::steady_clock::now();
  if (run.method == EvalMethod::Ppf) {
    const PpfResult r = s.ppf->detect(frame.depth_mm, im.camera);
    image_ms = msSince(t0);
    for (const auto& d : r.detections) estimates.push_back(estimateOf(d.obj_id, d.score, d.pose));
    for (const auto& [obj_id, ms] : r.object_ms) run.object_ms[obj_id] += ms + r.scene_ms;
    return estimates;
  }
  const DetectionResult r =
      run.method == EvalMethod::Vkpose ? s.detector->detect(frame, im.camera) : s.linemod->detect(frame, im.camera);
  // The first frame uploads the templates: set-up, like training, not per-image work.
  image_ms = msSince(t0);
  for (const auto& [stage, ms] : r.timings_ms)
    if (stage == stageName(Stage::upload)) image_ms -= ms;
  warnings.insert(r.warnings.begin(), r.warnings.end());
  if (run.method == EvalMethod::Vkpose && s.params.on_detections) s.params.on_detections(im, frame, r);
  for (const auto& d : r.detections)
    estimates.push_back(estimateOf(s.objects[static_cast<std::size_t>(d.bank)], d.score, d.pose));
  for (int obj_id : s.objects) run.object_ms[obj_id] += image_ms;
  return estimates;
}

/// Adds one image's estimates to the method's counts, outcomes and results.
void scoreImage(const Evaluator::State& s, MethodRun& run, const BopImage& im,
                const std::vector<PoseEstimate>& estimates, double image_ms) {
  std::vector<GroundTruthPose> gt;
  for (const auto& g : im.gt)
    if (s.models.count(g.obj_id)) gt.push_back(g);
  try {
    const ImageEvaluation evaluation = evaluateImage(estimates, gt, s.models, s.params.eval, &im.camera);
    for (const auto& [obj_id, c] : evaluation.counts) run.counts[obj_id] += c;
    for (const auto& [obj_id, v] : evaluation.by_visibility) run.by_visibility[obj_id] += v;
    for (std::size_t e = 0; e < estimates.size(); ++e)
      run.outcomes.push_back({estimates[e].obj_id, estimates[e].score, evaluation.matches[e].gt >= 0,
                              evaluation.matches[e].ignored});
  } catch (const InputError& e) {
    throw InputError(fmt::format("{} on scene {} image {}: {}", methodName(run.method), im.scene_id, im.image_id,
                                 e.what()));
  }
  for (const auto& e : estimates) run.results.push_back({im.scene_id, im.image_id, e, image_ms / 1e3});
}

MethodEvaluation finishRun(MethodRun& run, const std::vector<int>& objects, int images) {
  for (int obj_id : objects) {  // objects never seen still count (as zeros)
    run.counts[obj_id];
    run.by_visibility[obj_id];
  }
  MethodEvaluation m;
  m.method = run.method;
  m.summary = summarize(run.counts);
  const double n = std::max(images, 1);
  m.ms_per_image = run.total_ms / n;
  for (const auto& [obj_id, ms] : run.object_ms) m.object_ms_per_image[obj_id] = ms / n;
  m.results = std::move(run.results);
  m.outcomes = std::move(run.outcomes);
  m.by_visibility = std::move(run.by_visibility);
  return m;
}
}  // namespace

EvalReport Evaluator::run(std::size_t first, std::size_t count, const EvalProgress& progress) {
  State& s = *state_;
  const auto [begin, end] = imageRange();
  if (first < begin || count > end - first || first > end)
    throw InputError(fmt::format("images {} to {} are not among the run's images {} to {}", first, first + count,
                                 begin, end));
  EvalReport report;
  report.dataset = s.dataset.root;
  report.split = s.dataset.split;
  report.device = s.ctx.device().name;
  report.objects = s.objects;
  std::vector<MethodRun> runs;
  for (EvalMethod m : s.params.methods) runs.push_back({m, {}, 0, {}, {}, {}, {}});
  std::set<std::string> warnings;
  std::size_t step = 0;
  for (std::size_t i = first; i < first + count; ++i) {
    const BopImage& im = s.dataset.images[i];
    LinemodFrame frame;
    try {
      frame = loadFrame(im.rgb_path, s.params.no_depth ? std::string() : im.depth_path, im.camera.depth_scale);
    } catch (const InputError& e) {  // one bad file does not end a long run: it is named in the report
      report.skipped.push_back({im.scene_id, im.image_id, e.what()});
      step += runs.size();
      if (progress) progress(step, count * runs.size());
      continue;
    }
    ++report.images;
    for (MethodRun& run : runs) {
      double image_ms = 0;
      const std::vector<PoseEstimate> estimates = estimatesOf(s, run, im, frame, image_ms, warnings);
      run.total_ms += image_ms;
      scoreImage(s, run, im, estimates, image_ms);
      if (progress) progress(++step, count * runs.size());
    }
  }
  for (MethodRun& run : runs) report.methods.push_back(finishRun(run, s.objects, report.images));
  report.warnings.assign(warnings.begin(), warnings.end());
  return report;
}

EvalReport runEvaluation(GpuContext& ctx, const BopDataset& dataset, const std::map<int, TemplateBank>& banks,
                         const EvalRunParams& params, const EvalProgress& progress) {
  Evaluator evaluator(ctx, dataset, banks, params);
  const auto [begin, end] = evaluator.imageRange();
  EvalReport report = evaluator.run(begin, end - begin, progress);
  for (std::string& w : distanceCoverageWarnings(banks, dataset, begin, end, params.eval.min_visib_fract))
    report.warnings.push_back(std::move(w));
  return report;
}

std::vector<PrPoint> precisionRecallCurve(const std::vector<ScoredOutcome>& outcomes, int instances, int obj_id) {
  std::vector<const ScoredOutcome*> sorted;
  for (const ScoredOutcome& o : outcomes)
    if ((obj_id == 0 || o.obj_id == obj_id) && !o.ignored) sorted.push_back(&o);
  std::stable_sort(sorted.begin(), sorted.end(), [](const auto* a, const auto* b) { return a->score > b->score; });
  std::vector<PrPoint> curve;
  EvalCounts c;
  for (std::size_t i = 0; i < sorted.size(); ++i) {
    (sorted[i]->correct ? c.tp : c.fp) += 1;
    if (i + 1 < sorted.size() && sorted[i + 1]->score == sorted[i]->score) continue;  // one point per score
    EvalCounts at = c;
    at.fn = std::max(0, instances - c.tp);
    curve.push_back({sorted[i]->score, scoresOf(at)});
  }
  return curve;
}

std::string precisionRecallCsv(const EvalReport& report) {
  std::string out = "method,obj_id,threshold,precision,recall,f1,tp,fp,fn\n";
  for (const MethodEvaluation& m : report.methods) {
    auto add = [&](int obj_id, int instances) {
      for (const PrPoint& p : precisionRecallCurve(m.outcomes, instances, obj_id))
        out += fmt::format("{},{},{},{:.4f},{:.4f},{:.4f},{},{},{}\n", methodName(m.method), obj_id, p.threshold,
                           p.scores.precision, p.scores.recall, p.scores.f1, p.scores.tp, p.scores.fp, p.scores.fn);
    };
    add(0, m.summary.total.tp + m.summary.total.fn);
    for (const auto& [obj_id, s] : m.summary.objects) add(obj_id, s.tp + s.fn);
  }
  return out;
}

std::string precisionRecallSvg(const EvalReport& report) {
  // Precision and recall (y) of the estimates scoring at least each threshold (x), all objects
  // together, one colour per method; the line at 0.5 is where the README reads them.
  constexpr double W = 720, H = 440, left = 60, right = 200, top = 40, bottom = 50;
  const auto px = [&](double score) { return left + std::clamp(score, 0.0, 1.0) * (W - left - right); };
  const auto py = [&](double v) { return H - bottom - std::clamp(v, 0.0, 1.0) * (H - top - bottom); };
  static const char* colours[] = {"#1f77b4", "#d62728", "#2ca02c", "#9467bd"};
  std::string out = fmt::format(
      "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{0}\" height=\"{1}\" font-family=\"sans-serif\" "
      "font-size=\"12\">\n<rect width=\"{0}\" height=\"{1}\" fill=\"white\"/>\n"
      "<text x=\"{2}\" y=\"22\" font-size=\"14\">{3} ({4}): precision (solid) and recall (dashed) of the "
      "estimates scoring at least x</text>\n",
      W, H, left, report.dataset, report.split);
  for (int i = 0; i <= 10; ++i) {
    const double v = i / 10.0;
    out += fmt::format("<line x1=\"{0}\" y1=\"{1}\" x2=\"{2}\" y2=\"{1}\" stroke=\"#ddd\"/>"
                       "<text x=\"{3}\" y=\"{4}\" text-anchor=\"end\">{5:.1f}</text>\n",
                       px(0), py(v), px(1), left - 6, py(v) + 4, v);
    out += fmt::format("<line x1=\"{0}\" y1=\"{1}\" x2=\"{0}\" y2=\"{2}\" stroke=\"#ddd\"/>"
                       "<text x=\"{0}\" y=\"{3}\" text-anchor=\"middle\">{4:.1f}</text>\n",
                       px(v), py(0), py(1), py(0) + 16, v);
  }
  out += fmt::format("<text x=\"{}\" y=\"{}\" text-anchor=\"middle\">score threshold</text>\n", px(0.5), H - 10);
  out += fmt::format("<line x1=\"{0}\" y1=\"{1}\" x2=\"{0}\" y2=\"{2}\" stroke=\"black\" "
                     "stroke-dasharray=\"2,3\"/>\n",
                     px(0.5), py(0), py(1));
  for (std::size_t m = 0; m < report.methods.size(); ++m) {
    const MethodEvaluation& method = report.methods[m];
    const char* colour = colours[m % std::size(colours)];
    const auto curve = precisionRecallCurve(method.outcomes, method.summary.total.tp + method.summary.total.fn);
    std::string precision, recall;
    const PrPoint* at_half = nullptr;
    for (const PrPoint& p : curve) {
      precision += fmt::format("{:.1f},{:.1f} ", px(p.threshold), py(p.scores.precision));
      recall += fmt::format("{:.1f},{:.1f} ", px(p.threshold), py(p.scores.recall));
      if (p.threshold >= 0.5f) at_half = &p;
    }
    out += fmt::format("<polyline fill=\"none\" stroke=\"{}\" stroke-width=\"2\" points=\"{}\"/>\n", colour, precision);
    out += fmt::format("<polyline fill=\"none\" stroke=\"{}\" stroke-width=\"2\" stroke-dasharray=\"6,4\" "
                       "points=\"{}\"/>\n",
                       colour, recall);
    const double y = top + 20 + 50.0 * static_cast<double>(m);
    out += fmt::format("<text x=\"{}\" y=\"{}\" fill=\"{}\" font-weight=\"bold\">{}</text>\n", W - right + 12, y,
                       colour, methodName(method.method));
    out += fmt::format("<text x=\"{}\" y=\"{}\" fill=\"{}\">{}</text>\n", W - right + 12, y + 16, colour,
                       at_half ? fmt::format("at 0.5: P {:.3f} R {:.3f}", at_half->scores.precision,
                                             at_half->scores.recall)
                               : std::string("nothing scores 0.5"));
    if (at_half)
      out += fmt::format("<circle cx=\"{}\" cy=\"{}\" r=\"4\" fill=\"{}\"/>\n", px(0.5), py(at_half->scores.precision),
                         colour);
  }
  return out + "</svg>\n";
}

std::string evalReportJson(const EvalReport& report) {
  using nlohmann::json;
  const auto binsJson = [](const VisibilityRecall& v) {
    json bins = json::array();
    for (int b = 0; b < VisibilityRecall::kBins; ++b)
      bins.push_back({{"visib_fract", {static_cast<double>(b) / VisibilityRecall::kBins,
                                       static_cast<double>(b + 1) / VisibilityRecall::kBins}},
                      {"instances", v.instances[static_cast<std::size_t>(b)]},
                      {"found", v.found[static_cast<std::size_t>(b)]}});
    return bins;
  };
  json methods = json::object();
  for (const MethodEvaluation& m : report.methods) {
    json objects = json::object();
    for (const auto& [obj_id, s] : m.summary.objects) {
      const auto ms = m.object_ms_per_image.find(obj_id);
      const auto vis = m.by_visibility.find(obj_id);
      objects[std::to_string(obj_id)] = {
          {"precision", s.precision},
          {"recall", s.recall},
          {"f1", s.f1},
          {"ms_per_image", ms == m.object_ms_per_image.end() ? 0.0 : ms->second},
          {"tp", s.tp},
          {"fp", s.fp},
          {"fn", s.fn},
          {"by_visibility", binsJson(vis == m.by_visibility.end() ? VisibilityRecall{} : vis->second)}};
    }
    methods[methodName(m.method)] = {
        {"average",
         {{"precision", m.summary.mean.precision}, {"recall", m.summary.mean.recall}, {"f1", m.summary.mean.f1},
          {"ms_per_image", m.ms_per_image}}},
        {"objects", objects},
        {"by_visibility", binsJson(allObjects(m.by_visibility))}};
  }
  json skipped = json::array();
  for (const SkippedImage& s : report.skipped)
    skipped.push_back({{"scene_id", s.scene_id}, {"image_id", s.image_id}, {"reason", s.reason}});
  const json doc = {{"methods", methods},
                    {"dataset", report.dataset},
                    {"split", report.split},
                    {"images", report.images},
                    {"skipped", skipped},
                    {"warnings", report.warnings},
                    {"device", report.device}};
  return doc.dump(2) + "\n";
}

std::string evalReportTable(const EvalReport& report) {
  std::string out = fmt::format("{:<8} {:<8} {:>9} {:>7} {:>6} {:>5} {:>5} {:>5} {:>10}\n", "object", "method",
                                "precision", "recall", "F1", "TP", "FP", "FN", "ms/image");
  auto row = [&](const std::string& object, const MethodEvaluation& m, const ObjectScores& s, double ms) {
    out += fmt::format("{:<8} {:<8} {:>9.3f} {:>7.3f} {:>6.3f} {:>5} {:>5} {:>5} {:>10.1f}\n", object,
                       methodName(m.method), s.precision, s.recall, s.f1, s.tp, s.fp, s.fn, ms);
  };
  for (int obj_id : report.objects)
    for (const MethodEvaluation& m : report.methods) {
      const auto ms = m.object_ms_per_image.find(obj_id);
      row(std::to_string(obj_id), m, m.summary.objects.at(obj_id), ms == m.object_ms_per_image.end() ? 0.0 : ms->second);
    }
  for (const MethodEvaluation& m : report.methods) row("average", m, m.summary.mean, m.ms_per_image);
  // Found by visibility, when the dataset says how visible its instances are (without
  // scene_gt_info.json every instance is wholly visible and the line would say nothing new).
  for (const MethodEvaluation& m : report.methods) {
    const VisibilityRecall v = allObjects(m.by_visibility);
    const int top = VisibilityRecall::kBins - 1;
    int below_top = 0;
    for (int b = 0; b < top; ++b) below_top += v.instances[static_cast<std::size_t>(b)];
    if (below_top == 0) continue;
    out += fmt::format("{} found by visibility:", methodName(m.method));
    for (int b = 0; b < VisibilityRecall::kBins; ++b)
      out += fmt::format("{} {}: {} of {}", b == 0 ? "" : ",", visibilityBinName(b), v.found[static_cast<std::size_t>(b)],
                         v.instances[static_cast<std::size_t>(b)]);
    out += "\n";
  }
  return out;
}

}  // namespace vkpose
