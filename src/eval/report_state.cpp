// A run spread over processes: the run as JSON that a worker repeats (EvalJob), a slice's report
// as exact JSON (evalReportState), and the slices joined into the run's report
// (mergeEvalReports). Floats travel as the double they convert to exactly, which JSON writes in
// the shortest text that reads back as the same double: every estimate comes back bit for bit.
#include <set>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "vkpose/error.hpp"
#include "vkpose/evaluation.hpp"

namespace vkpose {
namespace {
using nlohmann::json;

constexpr int kStateVersion = 1;
constexpr int kJobVersion = 1;

json methodState(const MethodEvaluation& m) {
  json counts = json::array(), visibility = json::array(), object_ms = json::array();
  for (const auto& [obj_id, s] : m.summary.objects) counts.push_back({obj_id, s.tp, s.fp, s.fn});
  for (const auto& [obj_id, v] : m.by_visibility) visibility.push_back({obj_id, v.instances, v.found});
  for (const auto& [obj_id, ms] : m.object_ms_per_image) object_ms.push_back({obj_id, ms});
  json results = json::array(), outcomes = json::array();
  for (const BopResult& r : m.results) {
    const PoseEstimate& e = r.estimate;
    const std::vector<float> R(e.R.data(), e.R.data() + 9), t(e.t.data(), e.t.data() + 3);
    results.push_back({r.scene_id, r.im_id, e.obj_id, e.score, R, t, r.time_s});
  }
  for (const ScoredOutcome& o : m.outcomes) outcomes.push_back({o.obj_id, o.score, o.correct, o.ignored});
  return {{"method", methodName(m.method)}, {"ms_per_image", m.ms_per_image}, {"object_ms", object_ms},
          {"counts", counts},           {"by_visibility", visibility},      {"results", results},
          {"outcomes", outcomes}};
}

MethodEvaluation parseMethodState(const json& j) {
  MethodEvaluation m;
  m.method = parseEvalMethod(j.at("method").get<std::string>());
  m.ms_per_image = j.at("ms_per_image").get<double>();
  for (const json& o : j.at("object_ms")) m.object_ms_per_image[o.at(0).get<int>()] = o.at(1).get<double>();
  std::map<int, EvalCounts> counts;
  for (const json& c : j.at("counts")) counts[c.at(0).get<int>()] = {c.at(1).get<int>(), c.at(2).get<int>(), c.at(3).get<int>()};
  m.summary = summarize(counts);
  for (const json& v : j.at("by_visibility")) {
    VisibilityRecall& r = m.by_visibility[v.at(0).get<int>()];
    r.instances = v.at(1).get<decltype(r.instances)>();
    r.found = v.at(2).get<decltype(r.found)>();
  }
  for (const json& r : j.at("results")) {
    BopResult b;
    b.scene_id = r.at(0).get<int>();
    b.im_id = r.at(1).get<int>();
    b.estimate.obj_id = r.at(2).get<int>();
    b.estimate.score = r.at(3).get<float>();
    const auto R = r.at(4).get<std::vector<float>>();
    const auto t = r.at(5).get<std::vector<float>>();
    if (R.size() != 9 || t.size() != 3) throw InputError("an estimate's R needs 9 numbers and its t 3");
    std::copy(R.begin(), R.end(), b.estimate.R.data());
    std::copy(t.begin(), t.end(), b.estimate.t.data());
    b.time_s = r.at(6).get<double>();
    m.results.push_back(b);
  }
  for (const json& o : j.at("outcomes"))
    m.outcomes.push_back({o.at(0).get<int>(), o.at(1).get<float>(), o.at(2).get<bool>(), o.at(3).get<bool>()});
  return m;
}

/// The counts a summary was made from.
std::map<int, EvalCounts> countsOf(const EvalSummary& summary) {
  std::map<int, EvalCounts> counts;
  for (const auto& [obj_id, s] : summary.objects) counts[obj_id] = {s.tp, s.fp, s.fn};
  return counts;
}

/// The baselines' parameters by name, for the job file (one list, read and written alike).
template <typename Visit>
void ppfFields(PpfParams& p, Visit&& visit) {
  visit("model_step", p.model_step);
  visit("angle_bins", p.angle_bins);
  visit("model_samples", p.model_samples);
  visit("scene_step", p.scene_step);
  visit("max_scene_cells", p.max_scene_cells);
  visit("scene_ref_fraction", p.scene_ref_fraction);
  visit("cluster_distance", p.cluster_distance);
  visit("cluster_angle_deg", p.cluster_angle_deg);
  visit("pixel_step", p.pixel_step);
  visit("normal_step_px", p.normal_step_px);
  visit("normal_max_jump_m", p.normal_max_jump_m);
  visit("icp_poses", p.icp_poses);
  visit("icp_iterations", p.icp_iterations);
  visit("icp_levels", p.icp_levels);
  visit("icp_model_points", p.icp_model_points);
  visit("icp_crop", p.icp_crop);
  visit("max_poses", p.max_poses);
  visit("duplicate_distance", p.duplicate_distance);
}

const char* errorName(PoseErrorType type) {
  switch (type) {
    case PoseErrorType::ADD: return "add";
    case PoseErrorType::ADI: return "adi";
    case PoseErrorType::Proj2D: return "proj2d";
    case PoseErrorType::Auto: break;
  }
  return "auto";
}

PoseErrorType parseErrorName(const std::string& name) {
  for (PoseErrorType t : {PoseErrorType::Auto, PoseErrorType::ADD, PoseErrorType::ADI, PoseErrorType::Proj2D})
    if (name == errorName(t)) return t;
  throw InputError(fmt::format("unknown pose error '{}': auto, add, adi or proj2d", name));
}
}  // namespace

EvalReport mergeEvalReports(const std::vector<EvalReport>& parts) {
  if (parts.empty()) throw InputError("no reports to merge");
  const EvalReport& first = parts.front();
  EvalReport out;
  out.dataset = first.dataset;
  out.split = first.split;
  out.objects = first.objects;
  std::vector<std::map<int, EvalCounts>> counts(first.methods.size());
  std::vector<std::string> devices;
  std::set<std::string> warnings;
  for (const EvalReport& part : parts) {
    const bool same_methods =
        part.methods.size() == first.methods.size() &&
        std::equal(part.methods.begin(), part.methods.end(), first.methods.begin(),
                   [](const MethodEvaluation& a, const MethodEvaluation& b) { return a.method == b.method; });
    if (part.dataset != first.dataset || part.split != first.split || part.objects != first.objects || !same_methods)
      throw InputError(fmt::format("the reports are of different runs ({} {} and {} {})", first.dataset, first.split,
                                   part.dataset, part.split));
    if (std::find(devices.begin(), devices.end(), part.device) == devices.end()) devices.push_back(part.device);
    warnings.insert(part.warnings.begin(), part.warnings.end());
    out.skipped.insert(out.skipped.end(), part.skipped.begin(), part.skipped.end());
    out.images += part.images;
  }
  for (std::size_t d = 0; d < devices.size(); ++d) out.device += (d ? ", " : "") + devices[d];
  out.warnings.assign(warnings.begin(), warnings.end());

  const double images = std::max(out.images, 1);
  for (std::size_t k = 0; k < first.methods.size(); ++k) {
    MethodEvaluation m;
    m.method = first.methods[k].method;
    std::map<int, EvalCounts> sum;
    for (const EvalReport& part : parts) {
      const MethodEvaluation& p = part.methods[k];
      for (const auto& [obj_id, c] : countsOf(p.summary)) sum[obj_id] += c;
      for (const auto& [obj_id, v] : p.by_visibility) m.by_visibility[obj_id] += v;
      // Times are per image of each part: weigh each by its images.
      m.ms_per_image += p.ms_per_image * part.images / images;
      for (const auto& [obj_id, ms] : p.object_ms_per_image) m.object_ms_per_image[obj_id] += ms * part.images / images;
      m.results.insert(m.results.end(), p.results.begin(), p.results.end());
      m.outcomes.insert(m.outcomes.end(), p.outcomes.begin(), p.outcomes.end());
    }
    m.summary = summarize(sum);
    out.methods.push_back(std::move(m));
  }
  return out;
}

std::string evalReportState(const EvalReport& report) {
  json methods = json::array(), skipped = json::array();
  for (const MethodEvaluation& m : report.methods) methods.push_back(methodState(m));
  for (const SkippedImage& s : report.skipped)
    skipped.push_back({{"scene_id", s.scene_id}, {"image_id", s.image_id}, {"reason", s.reason}});
  const json doc = {{"vkpose_report_state", kStateVersion},
                    {"dataset", report.dataset},
                    {"split", report.split},
                    {"device", report.device},
                    {"objects", report.objects},
                    {"images", report.images},
                    {"skipped", skipped},
                    {"warnings", report.warnings},
                    {"methods", methods}};
  return doc.dump();
}

EvalReport parseEvalReportState(const std::string& text) {
  try {
    const json doc = json::parse(text);
    if (!doc.is_object() || doc.value("vkpose_report_state", 0) != kStateVersion)
      throw InputError(fmt::format("not a report state of version {}", kStateVersion));
    EvalReport r;
    r.dataset = doc.at("dataset").get<std::string>();
    r.split = doc.at("split").get<std::string>();
    r.device = doc.at("device").get<std::string>();
    r.objects = doc.at("objects").get<std::vector<int>>();
    r.images = doc.at("images").get<int>();
    for (const json& s : doc.at("skipped"))
      r.skipped.push_back({s.at("scene_id").get<int>(), s.at("image_id").get<int>(), s.at("reason").get<std::string>()});
    r.warnings = doc.at("warnings").get<std::vector<std::string>>();
    for (const json& m : doc.at("methods")) r.methods.push_back(parseMethodState(m));
    return r;
  } catch (const json::exception& e) {
    throw InputError(fmt::format("a report state that cannot be read: {}", e.what()));
  } catch (const InputError& e) {
    throw InputError(fmt::format("a report state that cannot be read: {}", e.what()));
  }
}

std::string evalJobJson(const EvalJob& job) {
  json banks = json::object(), methods = json::array(), ppf = json::object();
  for (const auto& [obj_id, path] : job.banks) banks[std::to_string(obj_id)] = path;
  for (EvalMethod m : job.params.methods) methods.push_back(methodName(m));
  PpfParams ppf_params = job.params.ppf;
  ppfFields(ppf_params, [&](const char* key, const auto& value) { ppf[key] = value; });
  const EvalParams& e = job.params.eval;
  const json doc = {
      {"vkpose_eval_job", kJobVersion},
      {"dataset", job.dataset},
      {"split", job.split},
      {"banks", banks},
      {"methods", methods},
      {"first_image", job.params.first_image},
      {"max_images", job.params.max_images},
      {"detector", json::parse(configJson(job.params.detector))},
      {"linemod",
       {{"depth_offset", job.params.linemod.depth_offset}, {"max_per_object", job.params.linemod.max_per_object}}},
      {"ppf", ppf},
      {"no_depth", job.params.no_depth},
      {"eval",
       {{"k_m", e.k_m}, {"error", errorName(e.error)}, {"min_visib_fract", e.min_visib_fract}, {"proj2d_px", e.proj2d_px}}}};
  return doc.dump(2) + "\n";
}

EvalJob parseEvalJob(const std::string& text) {
  try {
    const json doc = json::parse(text);
    if (!doc.is_object() || doc.value("vkpose_eval_job", 0) != kJobVersion)
      throw InputError(fmt::format("not an evaluation job of version {}", kJobVersion));
    EvalJob job;
    job.dataset = doc.at("dataset").get<std::string>();
    job.split = doc.at("split").get<std::string>();
    for (const auto& [key, path] : doc.at("banks").items()) job.banks[std::stoi(key)] = path.get<std::string>();
    EvalRunParams& p = job.params;
    p.methods.clear();
    for (const json& m : doc.at("methods")) p.methods.push_back(parseEvalMethod(m.get<std::string>()));
    p.first_image = doc.at("first_image").get<int>();
    p.max_images = doc.at("max_images").get<int>();
    p.detector = parseConfig(doc.at("detector").dump(), "the job's detector parameters");
    p.linemod.match = p.detector.match;
    p.linemod.depth_offset = doc.at("linemod").at("depth_offset").get<bool>();
    p.linemod.max_per_object = doc.at("linemod").at("max_per_object").get<int>();
    const json& ppf = doc.at("ppf");
    ppfFields(p.ppf, [&](const char* key, auto& value) { value = ppf.at(key).get<std::decay_t<decltype(value)>>(); });
    validatePpfParams(p.ppf);
    const json& e = doc.at("eval");
    p.eval.k_m = e.at("k_m").get<float>();
    p.eval.error = parseErrorName(e.at("error").get<std::string>());
    p.eval.min_visib_fract = e.at("min_visib_fract").get<float>();
    p.eval.proj2d_px = e.at("proj2d_px").get<float>();
    p.no_depth = doc.at("no_depth").get<bool>();
    return job;
  } catch (const json::exception& e) {
    throw InputError(fmt::format("an evaluation job that cannot be read: {}", e.what()));
  } catch (const std::logic_error& e) {  // std::stoi of a bank's key
    throw InputError(fmt::format("an evaluation job that cannot be read: {}", e.what()));
  }
}

}  // namespace vkpose
