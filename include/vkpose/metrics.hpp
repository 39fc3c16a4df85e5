#pragma once
// Pose errors, one-to-one matching and detection scores (DESIGN.md "Evaluation protocol"), and
// the BOP results CSV. ADD and ADI are those of Hinterstoisser et al. (ACCV 2012); the CSV is
// bop_toolkit's "bop19" format, so its scripts can score vkpose's output.
//
// The protocol: an estimate is correct for a ground-truth instance of its object when the pose
// error m < k_m * d (d: the object's diameter). Per image and object, estimates are taken best
// score first; each is matched to the still-unmatched instance with the smallest error among
// those it is correct for, or else is a false positive (so a second detection of an instance
// is one). Instances left unmatched are false negatives.
#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "vkpose/dataset.hpp"

namespace vkpose {

/// One pose an estimator returned for an image.
struct PoseEstimate {
  int obj_id = 0;
  float score = 0.f;                                ///< higher is better; decides the matching order
  Eigen::Matrix3f R = Eigen::Matrix3f::Identity();  ///< object-to-camera rotation
  Eigen::Vector3f t = Eigen::Vector3f::Zero();      ///< object-to-camera translation, metres
};

/// Exact nearest-neighbour distances to a fixed point set (a k-d tree whose nodes are the
/// medians of index ranges, stored in place). For ADI.
class PointIndex {
 public:
  PointIndex() = default;
  explicit PointIndex(std::vector<Eigen::Vector3f> points);

  /// The points, reordered into tree order.
  const std::vector<Eigen::Vector3f>& points() const { return points_; }
  /// Euclidean distance from q to the nearest point; infinity when there are no points.
  float nearestDistance(const Eigen::Vector3f& q) const;

 private:
  void build(std::size_t lo, std::size_t hi);
  void search(std::size_t lo, std::size_t hi, const Eigen::Vector3f& q, float& best_sq) const;

  std::vector<Eigen::Vector3f> points_;
  std::vector<uint8_t> axis_;  ///< split axis of the node at the midpoint of each range
};

/// ADD: mean distance between corresponding model points under the two poses (metres, like
/// the points).
float addError(const std::vector<Eigen::Vector3f>& points, const Eigen::Matrix3f& R_est, const Eigen::Vector3f& t_est,
               const Eigen::Matrix3f& R_gt, const Eigen::Vector3f& t_gt);

/// ADI: mean over the points under the ground-truth pose of the distance to the closest point
/// under the estimated pose. R_est must be a rotation (the search runs in its object frame; the
/// 1e-2 tolerance of the readers changes distances by at most about 1%).
float adiError(const PointIndex& points, const Eigen::Matrix3f& R_est, const Eigen::Vector3f& t_est,
               const Eigen::Matrix3f& R_gt, const Eigen::Vector3f& t_gt);

/// Which pose error scores an object.
enum class PoseErrorType {
  Auto,  ///< ADI for objects whose ModelInfo is symmetric, ADD otherwise
  ADD,   ///< ADD for every object
  ADI,   ///< ADI for every object
};

/// What scoring one object needs: its info (diameter, symmetry) and its model points.
struct EvalModel {
  ModelInfo info;
  PointIndex points;  ///< model vertices, metres, object frame
};

/// Throws InputError when there are no points or the diameter is not positive.
EvalModel makeEvalModel(const ModelInfo& info, std::vector<Eigen::Vector3f> points);

/// Every model of the dataset, its vertices read from evalModelPath (BOP's models_eval, in
/// millimetres).
std::map<int, EvalModel> loadEvalModels(const BopDataset& dataset);

struct EvalParams {
  float k_m = 0.15f;  ///< an estimate is correct when its error is below k_m * diameter
  PoseErrorType error = PoseErrorType::Auto;
  /// Instances whose visib_fract is below this are left out of the scores: not a false
  /// negative when missed, and an estimate matched to one counts as neither a true nor a false
  /// positive. They still take part in the matching. 0 (default) counts every instance.
  float min_visib_fract = 0.f;
};

/// ADD or ADI between an estimate and an instance of the same object, as `type` (Auto: from
/// model.info.symmetric) says. Metres.
float poseError(const EvalModel& model, const PoseEstimate& est, const GroundTruthPose& gt,
                PoseErrorType type = PoseErrorType::Auto);

/// Detections counted over any number of images.
struct EvalCounts {
  int tp = 0;  ///< estimates matched to an instance
  int fp = 0;  ///< estimates matched to none
  int fn = 0;  ///< instances no estimate matched
  EvalCounts& operator+=(const EvalCounts& o) {
    tp += o.tp;
    fp += o.fp;
    fn += o.fn;
    return *this;
  }
};

/// What became of one estimate.
struct EstimateMatch {
  int gt = -1;           ///< index into the image's ground truth; -1: a false positive
  float error = 0.f;     ///< the pose error to that instance, metres (0 when unmatched)
  bool ignored = false;  ///< matched an instance below min_visib_fract: neither TP nor FP
};

struct ImageEvaluation {
  std::vector<EstimateMatch> matches;  ///< parallel to the estimates
  std::map<int, EvalCounts> counts;    ///< by obj_id, for every object estimated or annotated
};

/// Matches one image's estimates to its ground truth, object by object (see the top of this
/// file); equal scores keep the estimates' order. Throws InputError when an estimate or an
/// instance names an object without a model, an estimate's R is not a rotation, or its score or
/// t is not finite.
ImageEvaluation evaluateImage(const std::vector<PoseEstimate>& estimates, const std::vector<GroundTruthPose>& gt,
                              const std::map<int, EvalModel>& models, const EvalParams& params = {});

struct ObjectScores {
  double precision = 0, recall = 0, f1 = 0;  ///< 0 where the ratio is 0/0
  int tp = 0, fp = 0, fn = 0;
};

ObjectScores scoresOf(const EvalCounts& counts);

struct EvalSummary {
  std::map<int, ObjectScores> objects;  ///< by obj_id
  /// Precision, recall and F1 averaged over the objects (macro average; F1 is the mean of the
  /// objects' F1, not the F1 of the means); tp, fp, fn summed.
  ObjectScores mean;
  /// Precision, recall and F1 of the summed counts (micro average).
  ObjectScores total;
};

EvalSummary summarize(const std::map<int, EvalCounts>& counts);

/// One row of a BOP results file.
struct BopResult {
  int scene_id = 0, im_id = 0;
  PoseEstimate estimate;
  double time_s = -1;  ///< the image's run time, seconds; -1: unknown
};

/// Writes bop_toolkit's results CSV: the header `scene_id,im_id,obj_id,score,R,t,time`, then one
/// line per estimate with R as 9 row-major numbers and t as 3 numbers in millimetres, each
/// separated by spaces. Numbers are written so that loadBopResults reads back the same floats.
void saveBopResults(const std::string& path, const std::vector<BopResult>& results);

/// Reads that CSV (the header line is optional, blank lines are skipped). Throws InputError with
/// the file and line for a wrong number of columns, a value that is not a finite number, a
/// negative id, or an R that is not a rotation.
std::vector<BopResult> loadBopResults(const std::string& path);

/// Scores results over every image of a dataset's split: images without results count their
/// instances as false negatives. Throws InputError for a result whose image is not in the
/// dataset.
EvalSummary evaluateDataset(const BopDataset& dataset, const std::map<int, EvalModel>& models,
                            const std::vector<BopResult>& results, const EvalParams& params = {});

}  // namespace vkpose
