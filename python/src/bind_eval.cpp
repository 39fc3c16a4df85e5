// Evaluation on a BOP dataset: vkpose.evaluate() in this process, and the pieces that
// vkpose.distributed spreads over Dask's workers (a run as a job text, an evaluator a worker
// keeps, a slice's report as text, the slices merged, the outputs written).
#include <filesystem>
#include <mutex>

#include <fmt/core.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include "arrays.hpp"
#include "vkpose/error.hpp"
#include "vkpose/evaluation.hpp"

namespace vkpose::python {

namespace {

/// The files a run writes: checked before it runs, written after.
struct EvalOutputs {
  std::string out, report, pr_curve;
};

EvalOutputs outputsOf(const py::object& out, const py::object& report, const py::object& pr_curve, bool overwrite,
                      const std::vector<EvalMethod>& methods) {
  EvalOutputs o;
  o.out = out.is_none() ? "" : pathOf(out, "out");
  o.report = report.is_none() ? "" : pathOf(report, "report");
  o.pr_curve = pr_curve.is_none() ? "" : pathOf(pr_curve, "pr_curve");
  if (!o.report.empty()) refuseOverwrite(o.report, overwrite);
  if (!o.pr_curve.empty()) refuseOverwrite(o.pr_curve, overwrite);
  if (!o.out.empty())
    for (EvalMethod method : methods) refuseOverwrite(methodResultsPath(o.out, method), overwrite);
  return o;
}

/// Writes the outputs and returns the report as evaluate() does.
py::dict finishReport(const EvalReport& r, const EvalOutputs& o) {
  if (!o.report.empty()) writeTextFile(o.report, evalReportJson(r), true);
  if (!o.pr_curve.empty()) writeTextFile(o.pr_curve, precisionRecallCsv(r), true);
  if (!o.out.empty())
    for (const MethodEvaluation& me : r.methods) saveBopResults(methodResultsPath(o.out, me.method), me.results);
  py::dict doc = py::module_::import("json").attr("loads")(evalReportJson(r));
  py::dict results;
  for (const MethodEvaluation& me : r.methods) {
    py::list rows;
    for (const BopResult& b : me.results) rows.append(resultRow(b));
    results[py::str(methodName(me.method))] = rows;
  }
  doc["results"] = results;
  doc["warnings"] = r.warnings;
  return doc;
}

/// The run evaluate() and vkpose.distributed.evaluate() take their arguments for.
EvalRunParams runParamsOf(const std::vector<std::string>& methods, const py::object& config, int images, float k_m,
                          float min_visib) {
  EvalRunParams params;
  params.detector = paramsOf(config);
  params.linemod.match = params.detector.match;
  params.methods.clear();
  for (const std::string& name : methods) params.methods.push_back(parseEvalMethod(name));
  params.max_images = images;
  params.eval.k_m = k_m;
  params.eval.min_visib_fract = min_visib;
  if (images < 0) valueError(fmt::format("images: {} is negative", images));
  if (!(k_m > 0)) valueError(fmt::format("k_m: {} is not positive", k_m));
  return params;
}

std::string datasetOf(const py::object& dataset) {
  const std::string root = pathOf(dataset, "dataset");
  if (!std::filesystem::is_directory(root)) valueError(root + ": no such dataset folder");
  return root;
}

/// One worker's evaluator: built from a job once, run on the slices it is given. A worker
/// running two tasks at once takes turns.
struct JobEvaluator {
  JobEvaluator(const std::string& job_text, const py::object& device) : job(parseEvalJob(job_text)), dev(deviceOf(device)) {
    py::gil_scoped_release nogil;
    std::map<int, TemplateBank> banks;
    for (const auto& [obj_id, path] : job.banks) banks.emplace(obj_id, loadBank(path));
    std::lock_guard<std::mutex> lock(dev->mutex);
    evaluator = std::make_unique<Evaluator>(dev->context, loadBopDataset(job.dataset, job.split), banks, job.params);
  }
  EvalJob job;
  std::shared_ptr<Device> dev;
  std::unique_ptr<Evaluator> evaluator;
};

const char* kEvaluateDoc = R"(Scores vkpose and the paper's baselines side by side on a BOP dataset, as `vkpose eval` does.
Returns the report `vkpose eval --report` writes, as a dict ({"methods": {name: {"average": ...,
"objects": ...}}, "dataset", "split", "images", "skipped", "device"}), plus "results": {method:
rows as read_bop_results gives them} and "warnings".

banks: {obj_id: Bank or bank path}. methods: any of 'vkpose', 'linemod', 'ppf'. config: the
detector's stage parameters (as Detector takes them). images: the first N (0: all). k_m: an
estimate is correct below k_m * diameter. out: BOP results CSV, METHOD_ put before the file
name; report: the JSON report; pr_curve: the precision-recall curves CSV (`vkpose eval
--pr-curve`). An image that cannot be read is skipped and listed under "skipped".
vkpose.distributed.evaluate() spreads the same run over a Dask cluster.)";

}  // namespace

void bindEval(py::module_& m) {
  m.def(
      "evaluate",
      [](const py::object& dataset, const py::dict& banks, const std::vector<std::string>& methods,
         const std::string& split, const py::object& config, int images, float k_m, float min_visib,
         const py::object& out, const py::object& report, const py::object& pr_curve, bool overwrite,
         const py::object& device, const py::object& progress) {
        const EvalRunParams params = runParamsOf(methods, config, images, k_m, min_visib);
        const EvalOutputs outputs = outputsOf(out, report, pr_curve, overwrite, params.methods);
        const std::string root = datasetOf(dataset);
        std::map<int, TemplateBank> bank_map;
        for (const auto& [key, value] : banks) {
          if (!py::isinstance<py::int_>(key)) valueError("banks: expected {obj_id (int): Bank or bank path}");
          const int id = key.cast<int>();
          bank_map.emplace(id, py::isinstance<TemplateBank>(value) ? value.cast<const TemplateBank&>()
                                                                    : loadBank(pathOf(value, "banks")));
        }
        const std::shared_ptr<Device> dev = deviceOf(device);
        const auto step = progressOf(progress, "evaluating");
        EvalReport r;
        {
          py::gil_scoped_release nogil;
          const BopDataset data = loadBopDataset(root, split);
          checkBanksAgainstDataset(bank_map, data);
          std::lock_guard<std::mutex> lock(dev->mutex);
          r = runEvaluation(dev->context, data, bank_map, params, step);
        }
        return finishReport(r, outputs);
      },
      py::arg("dataset"), py::arg("banks"), py::kw_only(),
      py::arg("methods") = std::vector<std::string>{"vkpose", "linemod", "ppf"}, py::arg("split") = "test",
      py::arg("config") = py::none(), py::arg("images") = 0, py::arg("k_m") = 0.15f, py::arg("min_visib") = 0.f,
      py::arg("out") = py::none(), py::arg("report") = py::none(), py::arg("pr_curve") = py::none(),
      py::arg("overwrite") = false, py::arg("device") = py::none(), py::arg("progress") = py::none(), kEvaluateDoc);

  // ---- what vkpose.distributed uses (not part of the documented API) ----
  m.def(
      "_eval_job",
      [](const py::object& dataset, const py::dict& banks, const std::vector<std::string>& methods,
         const std::string& split, const py::object& config, int images, float k_m, float min_visib,
         const py::object& out, const py::object& report, const py::object& pr_curve, bool overwrite) {
        EvalJob job;
        job.params = runParamsOf(methods, config, images, k_m, min_visib);
        outputsOf(out, report, pr_curve, overwrite, job.params.methods);
        job.dataset = std::filesystem::absolute(datasetOf(dataset)).string();
        job.split = split;
        for (const auto& [key, value] : banks) {
          if (!py::isinstance<py::int_>(key)) valueError("banks: expected {obj_id (int): bank path}");
          if (py::isinstance<TemplateBank>(value))
            valueError("banks: give bank files, not Bank objects: each worker reads its banks once from the file");
          const std::string path = pathOf(value, "banks");
          if (!std::filesystem::is_regular_file(path)) valueError(path + ": no such bank file");
          job.banks[key.cast<int>()] = std::filesystem::absolute(path).string();
        }
        return evalJobJson(job);
      },
      py::arg("dataset"), py::arg("banks"), py::kw_only(), py::arg("methods"), py::arg("split"), py::arg("config"),
      py::arg("images"), py::arg("k_m"), py::arg("min_visib"), py::arg("out"), py::arg("report"), py::arg("pr_curve"),
      py::arg("overwrite"), "A run as the text that vkpose.distributed's workers repeat; checks the arguments.");

  m.def(
      "_job_images",
      [](const std::string& job_text) {
        const EvalJob job = parseEvalJob(job_text);
        py::gil_scoped_release nogil;
        const BopDataset data = loadBopDataset(job.dataset, job.split);
        const std::size_t n = data.images.size();
        const auto first = static_cast<std::size_t>(job.params.first_image);
        const auto max = static_cast<std::size_t>(job.params.max_images);
        if (n == 0) throw InputError(fmt::format("{} has no annotated {} images", data.root, data.split));
        return std::make_pair(std::min(first, n), max > 0 ? std::min(n, first + max) : n);
      },
      py::arg("job"), "The images a job covers: (first, end) indices of the dataset's images.");

  py::class_<JobEvaluator>(m, "_Evaluator", "One worker's estimators for a job, kept between its batches")
      .def(py::init<const std::string&, const py::object&>(), py::arg("job"), py::arg("device") = py::none())
      .def(
          "run",
          [](JobEvaluator& e, std::size_t first, std::size_t count) {
            py::gil_scoped_release nogil;
            std::lock_guard<std::mutex> lock(e.dev->mutex);
            return evalReportState(e.evaluator->run(first, count));
          },
          py::arg("first"), py::arg("count"), "Images [first, first + count): their report, as text")
      .def_property_readonly("device", [](const JobEvaluator& e) { return e.dev->context.device().name; });

  m.def(
      "_merge_reports", [](const std::vector<std::string>& parts) {
        std::vector<EvalReport> reports;
        for (const std::string& p : parts) reports.push_back(parseEvalReportState(p));
        return evalReportState(mergeEvalReports(reports));
      },
      py::arg("parts"), "The slices' reports (in image order) as the run's report, as text");

  m.def(
      "_finish_report",
      [](const std::string& state, const py::object& out, const py::object& report, const py::object& pr_curve) {
        const EvalReport r = parseEvalReportState(state);
        std::vector<EvalMethod> methods;
        for (const MethodEvaluation& me : r.methods) methods.push_back(me.method);
        return finishReport(r, outputsOf(out, report, pr_curve, true, methods));
      },
      py::arg("state"), py::kw_only(), py::arg("out") = py::none(), py::arg("report") = py::none(),
      py::arg("pr_curve") = py::none(), "Writes a run's outputs and returns its report as evaluate() does");
}

}  // namespace vkpose::python
