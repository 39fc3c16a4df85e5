#pragma once
// Methods side by side on a BOP dataset (`vkpose eval`): the full pipeline (Detector) and the
// paper's two baselines (baselines.hpp) run on the same images, each scored with the paper's
// protocol (metrics.hpp), each timed per image.
#include <functional>
#include <map>
#include <string>
#include <vector>

#include "vkpose/baselines.hpp"
#include "vkpose/dataset.hpp"
#include "vkpose/detector.hpp"
#include "vkpose/metrics.hpp"

namespace vkpose {

enum class EvalMethod { Vkpose, Linemod, Ppf };

/// "vkpose", "linemod", "ppf".
std::string methodName(EvalMethod method);
/// The inverse; throws InputError naming the known methods.
EvalMethod parseEvalMethod(const std::string& name);

struct EvalRunParams {
  std::vector<EvalMethod> methods{EvalMethod::Vkpose, EvalMethod::Linemod, EvalMethod::Ppf};
  DetectorParams detector;
  LinemodBaselineParams linemod;
  PpfParams ppf;
  EvalParams eval;
  int max_images = 0;  ///< the first N images of the split; 0: all
  /// Called with vkpose's result on each image (e.g. to write its overlay and JSON).
  std::function<void(const BopImage&, const LinemodFrame&, const DetectionResult&)> on_detections;
};

/// One method's scores and times.
struct MethodEvaluation {
  EvalMethod method = EvalMethod::Vkpose;
  /// Per object (every evaluated object, found or not) and averaged (macro: the mean of the
  /// objects' precision, recall and F1).
  EvalSummary summary;
  /// Wall-clock per image, milliseconds, averaged over the images: the method's whole work on
  /// an image (every object), model training and file reading left out.
  double ms_per_image = 0;
  /// Per object: the time that object's own work took per image. ppf matches object by
  /// object (its shared scene preparation is counted in each object's figure); vkpose and
  /// linemod find all objects in one pass, so each object's figure is the whole pass.
  std::map<int, double> object_ms_per_image;
  std::vector<BopResult> results;  ///< every estimate, for the BOP CSV
};

struct EvalReport {
  std::string dataset, split, device;
  std::vector<int> objects;  ///< the evaluated obj_ids, ascending
  int images = 0;
  std::vector<MethodEvaluation> methods;  ///< in the order asked for
  std::vector<std::string> warnings;      ///< e.g. a bank trained for another focal length (once each)
};

/// Called after each image of each method: (steps done, steps in all).
using EvalProgress = std::function<void(std::size_t, std::size_t)>;

/// Checks that every bank's object is in the dataset and that the bank's diameter matches the
/// model's (within 10%: a bank of another object or in other units); InputError otherwise.
void checkBanksAgainstDataset(const std::map<int, TemplateBank>& banks, const BopDataset& dataset);

/// Runs the methods on the dataset's images and scores them. `banks` maps BOP obj_id to the
/// object's bank; the evaluated objects are the banks' (ground truth of other objects is left
/// out). vkpose and linemod need banks; ppf trains on the dataset's models/obj_%06d.ply. With
/// only ppf and no banks, every object of the dataset is evaluated. Throws InputError for a
/// bank the dataset has no object for, a method asked for twice, or nothing to evaluate.
EvalReport runEvaluation(GpuContext& ctx, const BopDataset& dataset, const std::map<int, TemplateBank>& banks,
                         const EvalRunParams& params = {}, const EvalProgress& progress = {});

/// The report as JSON:
/// {"methods": {"vkpose": {"average": {"precision", "recall", "f1", "ms_per_image"},
///                         "objects": {"1": {"precision", "recall", "f1", "ms_per_image",
///                                           "tp", "fp", "fn"}, ...}}, ...},
///  "dataset": ..., "split": ..., "images": N, "device": ...}
std::string evalReportJson(const EvalReport& report);

/// The side-by-side table: a row per object and method, then each method's average.
std::string evalReportTable(const EvalReport& report);

/// Where the BOP results CSV of a method goes for `--out PATH`: METHOD_ before PATH's file
/// name (results/lmo-test.csv -> results/ppf_lmo-test.csv), bop_toolkit's naming.
std::string methodResultsPath(const std::string& path, EvalMethod method);

}  // namespace vkpose
