#pragma once
// Evaluation on BOP datasets (`vkpose eval`): reading datasets (scenes, ground truth, cameras,
// models), the paper's protocol (ADD/ADI under k_m * d, one-to-one matching, precision, recall,
// F1), the BOP results CSV, writing BOP files (synth), and the full pipeline and the paper's two
// baselines (LINEMOD alone, PPF) run side by side on the same images.
#include <array>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "vkpose/bank.hpp"
#include "vkpose/config.hpp"
#include "vkpose/detector.hpp"
#include "vkpose/device.hpp"
#include "vkpose/frame.hpp"
#include "vkpose/geometry.hpp"

namespace vkpose {

// ---- BOP datasets ----------------------------------------------------------------------

/// One annotated object instance of an image (BOP scene_gt.json, with visib_fract from
/// scene_gt_info.json when the dataset has it).
struct GroundTruthPose {
  int obj_id = 0;
  Eigen::Matrix3f R = Eigen::Matrix3f::Identity();  ///< object-to-camera rotation (cam_R_m2c)
  Eigen::Vector3f t = Eigen::Vector3f::Zero();      ///< object-to-camera translation, metres
  float visib_fract = 1.f;                          ///< visible share of the object's silhouette, 0..1
};

/// One entry of a BOP scene_gt_info.json (the same order as the image's scene_gt.json list).
struct GroundTruthInfo {
  cv::Rect bbox_obj;        ///< box of the whole silhouette, pixels ([-1 -1 -1 -1] in BOP: none)
  cv::Rect bbox_visib;      ///< box of the visible part, pixels
  int px_count_all = 0;     ///< pixels of the whole silhouette
  int px_count_valid = 0;   ///< ... of which with a valid depth
  int px_count_visib = 0;   ///< visible pixels
  float visib_fract = 1.f;  ///< px_count_visib / px_count_all
};

/// One object of BOP's models_info.json.
struct ModelInfo {
  int obj_id = 0;
  float diameter = 0.f;                                 ///< largest distance between two model points, metres
  Eigen::Vector3f bbox_min = Eigen::Vector3f::Zero();   ///< min_x, min_y, min_z, metres
  Eigen::Vector3f bbox_size = Eigen::Vector3f::Zero();  ///< size_x, size_y, size_z, metres
  /// The file lists discrete or continuous symmetries: poses are scored with ADI, not ADD.
  bool symmetric = false;
};

/// One image of a BOP split with its camera and ground truth.
struct BopImage {
  int scene_id = 0, image_id = 0;
  std::string rgb_path, depth_path;  ///< rgb/%06d.png (or .jpg), depth/%06d.png
  Camera camera;                     ///< scene_camera.json's cam_K and depth_scale, size from camera.json
  std::vector<GroundTruthPose> gt;
  std::vector<GroundTruthInfo> gt_info;  ///< parallel to gt; empty when the scene has no scene_gt_info.json
};

/// A BOP dataset: models and the images of one split that have ground truth.
struct BopDataset {
  std::string root;
  std::string split;
  Camera camera;                    ///< the dataset's camera.json
  std::map<int, ModelInfo> models;  ///< by obj_id
  std::vector<BopImage> images;     ///< sorted by (scene_id, image_id)

  std::string modelPath(int obj_id) const;  ///< root/models/obj_%06d.ply
  /// root/models_eval/obj_%06d.ply (BOP's decimated models for pose errors) when it exists,
  /// otherwise modelPath(obj_id).
  std::string evalModelPath(int obj_id) const;
};

/// scene_gt.json: image id -> instances, in the file's order. visib_fract stays 1.
std::map<int, std::vector<GroundTruthPose>> loadSceneGt(const std::string& path);

/// scene_gt_info.json: image id -> per-instance visibility, in the file's order.
std::map<int, std::vector<GroundTruthInfo>> loadSceneGtInfo(const std::string& path);

/// scene_camera.json: image id -> camera. cam_K gives fx, fy, cx, cy and depth_scale the
/// depth scale when present; the image size and a missing depth_scale come from `base`.
std::map<int, Camera> loadSceneCamera(const std::string& path, const Camera& base = {});

/// models_info.json: obj_id -> diameter, box and symmetry flag, in metres.
std::map<int, ModelInfo> loadModelsInfo(const std::string& path);

/// Reads root/camera.json, root/models/models_info.json and every scene root/split/%06d/ with
/// its scene_gt.json and scene_camera.json (scene_gt_info.json optional: visib_fract 1 without
/// it). Images are those of scene_gt.json; each needs its camera entry, a depth PNG and an rgb
/// PNG or JPG, and every annotated obj_id must be in models_info.json.
BopDataset loadBopDataset(const std::string& root, const std::string& split = "test");

/// A pose file of Tejani et al. 2014 (posesN.txt): the number of instances on the first line,
/// then that many 4x4 row-major object-to-camera matrices, translation in metres. Throws
/// InputError with the file and the line when the count does not match the matrices, a value
/// is not a finite number, the last row is not 0 0 0 1, or R is not a rotation
/// (an entry of R^T R - I over 1e-2, or det R < 0). Rotations are returned as read, not
/// re-orthonormalized.
std::vector<Pose> loadTejaniPoses(const std::string& path);

// ---- the protocol: pose errors, one-to-one matching, scores, the results CSV -----------

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
  /// Mean 2D projection distance of the model points under the two poses, pixels, with the
  /// image's camera (for symmetric objects, ADI's rule: to the nearest projected point): the
  /// usual score of colour-only methods (correct under EvalParams::proj2d_px, 5 px, whatever
  /// the diameter). Blind to depth along the ray.
  Proj2D,
};

/// Proj2D: mean distance in pixels between the model points projected under the two poses.
float proj2dError(const std::vector<Eigen::Vector3f>& points, const Eigen::Matrix3f& R_est, const Eigen::Vector3f& t_est,
                  const Eigen::Matrix3f& R_gt, const Eigen::Vector3f& t_gt, const Camera& camera);

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
  /// PoseErrorType::Proj2D: an estimate is correct under this many pixels.
  float proj2d_px = 5.f;
};

/// ADD or ADI between an estimate and an instance of the same object, as `type` (Auto: from
/// model.info.symmetric) says, metres; or Proj2D in pixels, which needs the image's camera
/// (InputError without it).
float poseError(const EvalModel& model, const PoseEstimate& est, const GroundTruthPose& gt,
                PoseErrorType type = PoseErrorType::Auto, const Camera* camera = nullptr);

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

/// Instances found and annotated by how much of each is visible: where a method's misses are.
/// Bins of visib_fract 0.2 wide ([0, 0.2), [0.2, 0.4), ..., [0.8, 1]); instances below
/// EvalParams::min_visib_fract are left out, as from the counts.
struct VisibilityRecall {
  static constexpr int kBins = 5;
  std::array<int, kBins> instances{};
  std::array<int, kBins> found{};  ///< of those, matched by an estimate
  /// The bin of a visib_fract (values outside 0..1 go to the nearest end).
  static int binOf(float visib_fract);
  VisibilityRecall& operator+=(const VisibilityRecall& o) {
    for (int b = 0; b < kBins; ++b) {
      instances[b] += o.instances[b];
      found[b] += o.found[b];
    }
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
  std::map<int, VisibilityRecall> by_visibility;  ///< by obj_id, for every object annotated
};

/// Matches one image's estimates to its ground truth, object by object (see the top of this
/// file); equal scores keep the estimates' order. Throws InputError when an estimate or an
/// instance names an object without a model, an estimate's R is not a rotation, or its score or
/// t is not finite.
ImageEvaluation evaluateImage(const std::vector<PoseEstimate>& estimates, const std::vector<GroundTruthPose>& gt,
                              const std::map<int, EvalModel>& models, const EvalParams& params = {},
                              const Camera* camera = nullptr);

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

// ---- writing BOP files -----------------------------------------------------------------

/// A continuous rotational symmetry of a model (BOP's symmetries_continuous): the axis and a
/// point on it, object frame.
struct ContinuousSymmetry {
  Eigen::Vector3f axis = Eigen::Vector3f::UnitZ();
  Eigen::Vector3f offset_m = Eigen::Vector3f::Zero();
};

/// One model of a dataset: its mesh (metres) and symmetries.
struct BopModel {
  int obj_id = 0;
  const Mesh* mesh = nullptr;
  std::vector<ContinuousSymmetry> symmetries;
  /// Turns that map the model onto itself, shape and colour (exactSymmetries), object frame.
  std::vector<Pose> discrete_symmetries = {};
};

/// Writes the mesh in millimetres as a binary little-endian PLY (x y z, nx ny nz, and red
/// green blue when it has colours; faces as uchar-counted int lists), what BOP's models/ hold.
/// InputError when the file exists and `overwrite` is false, or it cannot be written.
void writePlyMillimetres(const Mesh& mesh, const std::string& path, bool overwrite);

/// models_info.json: diameter, min_x.. and size_x.. in mm, and symmetries_continuous and
/// symmetries_discrete (each a row-major 4x4 matrix, translation in mm) where the model has any.
std::string modelsInfoJson(const std::vector<BopModel>& models);

/// camera.json: cx, cy, depth_scale, fx, fy, height, width.
std::string cameraJson(const Camera& camera);

/// scene_camera.json: per image cam_K (row-major 3x3) and depth_scale.
std::string sceneCameraJson(const std::map<int, Camera>& cameras);

/// scene_gt.json: per image the instances' cam_R_m2c (row-major), cam_t_m2c (mm) and obj_id.
std::string sceneGtJson(const std::map<int, std::vector<GroundTruthPose>>& gt);

/// scene_gt_info.json: per image the instances' bbox_obj, bbox_visib, px_count_all,
/// px_count_valid, px_count_visib and visib_fract.
std::string sceneGtInfoJson(const std::map<int, std::vector<GroundTruthInfo>>& info);

// ---- the baselines' parameters --------------------------------------------------------

struct LinemodBaselineParams {
  MatchParams match;  ///< the similarity threshold, as the detector's stage 2
  /// Move each match's template along its viewing ray by the mean difference between the
  /// scene depth and the template's rendered depth (the cluster score's depth offset, one
  /// GPU submit for all matches). Off: the pose sits at the template's training distance,
  /// which is up to half a radius step away from the instance.
  bool depth_offset = true;
  /// Detections kept per object (bank) and image: the best by similarity. An 8-object LM-O
  /// frame gives 1.09 M raw matches, whose one-to-one scoring would not finish; 0 keeps all.
  int max_per_object = 100;
};

/// Distances relative to the object's diameter follow OpenCV's conventions; absolute ones are
/// in metres. OpenCV's PPF pairs every scene reference point with every sampled scene point
/// and its training walks whole hash chains, so time grows with the square of the sampled
/// points on both sides; the defaults are what ran in seconds per object on a 640x480 LM-O
/// frame on 2 cores and still found its driller (docs/evaluation.md).
struct PpfParams {
  /// Model sampling and PPF distance step, fraction of the model's bounding-box diagonal
  /// (OpenCV's relativeSamplingStep). OpenCV divides each axis of the box into 1 / step cells,
  /// so 0.1 keeps about 300 points of an LM-O object (spacing about 0.06 of its diameter);
  /// 0.05 keeps about 1,400 and trains for minutes.
  float model_step = 0.1f;
  int angle_bins = 30;  ///< PPF angle quantization (OpenCV's numAngles; Drost et al.: 30)
  int model_samples = 20000;  ///< points sampled on the mesh surface before OpenCV's own sampling
  /// Scene sampling cell, fraction of the model's diameter (Drost et al.: 0.05); OpenCV
  /// quantizes the scene's box in equal numbers of cells per axis, at most `max_scene_cells`
  /// per axis, so a scene deeper or wider than max_scene_cells cells gets coarser ones.
  float scene_step = 0.05f;
  int max_scene_cells = 150;
  float scene_ref_fraction = 0.1f;  ///< share of the sampled scene points used as reference points
  /// Voted poses closer than these (fraction of the diameter; rotation angle, degrees) join one
  /// cluster, whose votes add up (Drost et al.'s pose clustering).
  float cluster_distance = 0.1f;
  float cluster_angle_deg = 12.f;
  int pixel_step = 2;               ///< back-project every n-th pixel of the depth image
  int normal_step_px = 2;           ///< scene normals from depth differences this far either side
  float normal_max_jump_m = 0.01f;  ///< ... not across a depth edge larger than this
  /// ICP (OpenCV's point-to-plane ICP with robust rejection) on this many best-voted poses.
  int icp_poses = 10;
  int icp_iterations = 50;
  int icp_levels = 4;
  int icp_model_points = 1000;  ///< model points ICP aligns (a uniform subset of the samples)
  /// Scene points farther than this many diameters from the pose's centre are left out of its
  /// ICP (the object's neighbourhood, not the whole room).
  float icp_crop = 0.75f;
  /// Poses reported per object and image: the best-voted after ICP, dropping any whose centre
  /// lies within `duplicate_distance` diameters of a better one's (one instance, two poses).
  /// 3: the most instances of an object in a Tejani et al. scene.
  int max_poses = 3;
  float duplicate_distance = 0.25f;
};
/// Throws InputError naming the bad value.
void validatePpfParams(const PpfParams& params);

// ---- methods side by side -------------------------------------------------------------

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
  int max_images = 0;  ///< N images of the split from first_image on; 0: all
  int first_image = 0;  ///< the images before this one are left out (a slice of a run)
  /// Run as if the dataset had no depth images: vkpose detects colour-only (the other
  /// methods need depth and are refused).
  bool no_depth = false;
  /// Called with vkpose's result on each image (e.g. to write its overlay and JSON).
  std::function<void(const BopImage&, const LinemodFrame&, const DetectionResult&)> on_detections;
};

/// What became of one estimate in the one-to-one matching, with its score: for the
/// precision-recall curve.
struct ScoredOutcome {
  int obj_id = 0;
  float score = 0.f;
  bool correct = false;  ///< matched an instance (a true positive)
  bool ignored = false;  ///< matched an instance below min_visib_fract: neither TP nor FP
};

/// One point of a precision-recall curve: the scores of the estimates whose score is at least
/// `threshold`. The matching is greedy by score, so dropping the estimates below a threshold
/// leaves the matches of those above it as they were.
struct PrPoint {
  float threshold = 0.f;
  ObjectScores scores;
};

/// The curve of `outcomes` against `instances` counted ground-truth instances (of obj_id, or of
/// every object for obj_id 0), one point per distinct score, highest first.
std::vector<PrPoint> precisionRecallCurve(const std::vector<ScoredOutcome>& outcomes, int instances, int obj_id = 0);

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
  std::vector<ScoredOutcome> outcomes;  ///< every estimate's outcome, for precisionRecallCurve
  /// Per object (every evaluated object): its instances found by how visible they are.
  std::map<int, VisibilityRecall> by_visibility;
};

/// An image a run could not read (a missing or corrupt file): left out of the scores and named
/// in the report, while the run goes on with the other images.
struct SkippedImage {
  int scene_id = 0, image_id = 0;
  std::string reason;
};

struct EvalReport {
  std::string dataset, split, device;
  std::vector<int> objects;  ///< the evaluated obj_ids, ascending
  int images = 0;            ///< images scored (the skipped ones are not)
  std::vector<SkippedImage> skipped;
  std::vector<MethodEvaluation> methods;  ///< in the order asked for
  std::vector<std::string> warnings;      ///< e.g. a bank trained for another focal length (once each)
};

/// Called after each image of each method: (steps done, steps in all).
using EvalProgress = std::function<void(std::size_t, std::size_t)>;

/// Checks that every bank's object is in the dataset and that the bank's diameter matches the
/// model's (within 10%: a bank of another object or in other units); InputError otherwise.
void checkBanksAgainstDataset(const std::map<int, TemplateBank>& banks, const BopDataset& dataset);

/// One warning per evaluated object with instances (in images [first, end), at least
/// `min_visib` visible) whose centre lies nearer or farther from the camera than its bank was
/// trained at (its radii, widened by half a step or 5 %): LINEMOD matches a view at about the
/// size it was trained at, so such instances are mostly missed, and a user should see why
/// before reading the recall. Empty when every instance is covered.
std::vector<std::string> distanceCoverageWarnings(const std::map<int, TemplateBank>& banks, const BopDataset& dataset,
                                                  std::size_t first, std::size_t end, float min_visib = 0.f);

/// Runs the methods on the dataset's images and scores them. `banks` maps BOP obj_id to the
/// object's bank; the evaluated objects are the banks' (ground truth of other objects is left
/// out). vkpose and linemod need banks; ppf trains on the dataset's models/obj_%06d.ply. With
/// only ppf and no banks, every object of the dataset is evaluated. Throws InputError for a
/// bank the dataset has no object for, a method asked for twice, or nothing to evaluate. The
/// report's warnings include distanceCoverageWarnings for its images.
EvalReport runEvaluation(GpuContext& ctx, const BopDataset& dataset, const std::map<int, TemplateBank>& banks,
                         const EvalRunParams& params = {}, const EvalProgress& progress = {});

/// The estimators of a run (vkpose's detector with its banks on the device, the baselines, the
/// models the poses are scored against), built once and then run on any images of the dataset:
/// what a worker of a run spread over processes keeps between its batches. runEvaluation is
/// an Evaluator run once on all of its images.
class Evaluator {
 public:
  /// Checks as runEvaluation does; the device must outlive the Evaluator.
  Evaluator(GpuContext& ctx, BopDataset dataset, const std::map<int, TemplateBank>& banks, const EvalRunParams& params);
  ~Evaluator();
  Evaluator(const Evaluator&) = delete;
  Evaluator& operator=(const Evaluator&) = delete;

  /// The images the parameters select (first_image, max_images): indices [first, second) of
  /// the dataset's images.
  std::pair<std::size_t, std::size_t> imageRange() const;
  /// Runs and scores images [first, first + count) (indices into the dataset's images, within
  /// imageRange()): a report of those images alone, which mergeEvalReports joins with the
  /// others'. An image that cannot be read is skipped and named in the report.
  EvalReport run(std::size_t first, std::size_t count, const EvalProgress& progress = {});

  struct State;  ///< the estimators and what they score against (evaluation.cpp)

 private:
  std::unique_ptr<State> state_;
};

/// One report of a run from the reports of its slices (Evaluator::run on consecutive images,
/// given in image order): counts and visibility summed, estimates and outcomes joined in image
/// order, times averaged over the images, warnings and device names each once. Equal to the
/// report of one Evaluator::run over all of them, times aside. InputError for reports of
/// different runs (dataset, split, objects or methods differ) or none.
EvalReport mergeEvalReports(const std::vector<EvalReport>& parts);

/// Every field of a report as JSON, floats so that they read back equal: how a slice's report
/// travels from a worker process. parseEvalReportState reads it back (InputError when it is
/// not such a document).
std::string evalReportState(const EvalReport& report);
EvalReport parseEvalReportState(const std::string& json);

/// A run as another process can repeat it: the dataset folder and split, the bank files by
/// obj_id and every parameter. What `vkpose eval --workers` hands to vkpose.distributed.
struct EvalJob {
  std::string dataset, split = "test";
  std::map<int, std::string> banks;  ///< obj_id -> bank file
  EvalRunParams params;              ///< on_detections does not travel
};
std::string evalJobJson(const EvalJob& job);
/// InputError naming what is wrong. linemod's match parameters are the detector's (as the CLI
/// and Python set them).
EvalJob parseEvalJob(const std::string& json);

/// The report as JSON:
/// {"methods": {"vkpose": {"average": {"precision", "recall", "f1", "ms_per_image"},
///                         "objects": {"1": {"precision", "recall", "f1", "ms_per_image",
///                                           "tp", "fp", "fn", "by_visibility"}, ...},
///                         "by_visibility": [...]}, ...},
///  "dataset": ..., "split": ..., "images": N, "skipped": [{"scene_id", "image_id", "reason"}],
///  "device": ...}
/// by_visibility (per object, and for all objects together): a VisibilityRecall bin each,
/// {"visib_fract": [from, to], "instances": n, "found": k}.
std::string evalReportJson(const EvalReport& report);

/// The precision-recall curves of a report as CSV: `method,obj_id,threshold,precision,recall,f1,
/// tp,fp,fn`, a curve per method for all objects together (obj_id 0) and per object.
std::string precisionRecallCsv(const EvalReport& report);
/// The same curves (all objects together, a colour per method) as an SVG plot: precision and
/// recall against the score threshold, with each method's figures at score 0.5.
std::string precisionRecallSvg(const EvalReport& report);

/// The side-by-side table: a row per object and method, then each method's average, then,
/// when not every instance is (almost) wholly visible, each method's instances found by
/// visibility (all objects together).
std::string evalReportTable(const EvalReport& report);

/// Where the BOP results CSV of a method goes for `--out PATH`: METHOD_ before PATH's file
/// name (results/lmo-test.csv -> results/ppf_lmo-test.csv), bop_toolkit's naming.
std::string methodResultsPath(const std::string& path, EvalMethod method);

}  // namespace vkpose
