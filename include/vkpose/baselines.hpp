#pragma once
// The two baselines the paper compares against (He et al., table of F1 scores), run by
// `vkpose eval` side by side with the full pipeline:
//
// - LINEMOD alone (Hinterstoisser et al., ACCV 2012, without its post-processing): every raw
//   match over the similarity threshold is a detection with its template's pose, turned onto
//   the viewing ray through the match, scored by its similarity. Many overlapping matches per
//   instance: the duplicates are what the paper's clustering and verification remove.
// - Drost et al. (CVPR 2010), "Model globally, match locally": point-pair features voted in a
//   Hough space, through OpenCV's cv::ppf_match_3d with its ICP on the best poses. Depth only.
//
// Both take the same frames as the Detector and return plain structs; OpenCV's surface
// matching types stay inside src/eval/ppf_baseline.cpp.
#include <map>
#include <memory>
#include <vector>

#include <opencv2/core.hpp>

#include "vkpose/camera.hpp"
#include "vkpose/cluster_score.hpp"
#include "vkpose/detector.hpp"
#include "vkpose/matcher.hpp"
#include "vkpose/mesh.hpp"
#include "vkpose/render.hpp"
#include "vkpose/template_bank.hpp"

namespace vkpose {

// ---- LINEMOD alone ---------------------------------------------------------------------

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

/// Stages 1 and 2 of the detector and nothing else: one detection per raw match, the best
/// max_per_object of each object.
class LinemodBaseline {
 public:
  /// Banks as the Detector takes them (sharing the first bank's pyramid and modalities).
  LinemodBaseline(GpuContext& ctx, std::vector<TemplateBank> banks, LinemodBaselineParams params = {});
  ~LinemodBaseline();
  LinemodBaseline(const LinemodBaseline&) = delete;
  LinemodBaseline& operator=(const LinemodBaseline&) = delete;

  /// The best max_per_object matches of each object as Detections (result.matches counts all
  /// of them): score = similarity / 100, x and y the object centre the
  /// match implies, pose = templatePose() there (with the depth offset when enabled), templates
  /// = 1. Best similarity first. Throws InputError for a frame without depth or a camera whose
  /// principal point lies outside the frame.
  DetectionResult detect(const LinemodFrame& frame, const Camera& camera);

  const std::vector<TemplateBank>& banks() const { return banks_; }

 private:
  GpuContext& ctx_;
  std::vector<TemplateBank> banks_;
  LinemodBaselineParams params_;
  std::unique_ptr<LinemodMatcher> matcher_;
  std::unique_ptr<ClusterScorer> scorer_;
};

// ---- Drost et al.'s point-pair features ------------------------------------------------

/// Distances relative to the object's diameter follow OpenCV's conventions; absolute ones are
/// in metres. OpenCV's PPF pairs every scene reference point with every sampled scene point
/// and its training walks whole hash chains, so time grows with the square of the sampled
/// points on both sides; the defaults are what ran in seconds per object on a 640x480 LM-O
/// frame on 2 cores and still found its driller (the note in README.md "vkpose eval").
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

struct PpfDetection {
  int obj_id = 0;
  float score = 0.f;  ///< PPF votes of the pose's cluster
  Pose pose;          ///< object-to-camera, metres, after ICP
  float icp_residual = 0.f;
};

struct PpfResult {
  std::vector<PpfDetection> detections;  ///< by object (in the order they were added), best score first
  std::size_t scene_points = 0;          ///< back-projected points with a normal
  double scene_ms = 0;                   ///< back-projection and normals, shared by all objects
  std::map<int, double> object_ms;       ///< per object: voting, clustering and ICP
  double total_ms = 0;
};

/// One trained PPF model per object; detect() matches each against a depth image.
class PpfBaseline {
 public:
  explicit PpfBaseline(PpfParams params = {});
  ~PpfBaseline();
  PpfBaseline(const PpfBaseline&) = delete;
  PpfBaseline& operator=(const PpfBaseline&) = delete;

  /// Samples the mesh's surface (area-weighted, normals interpolated from the vertices) and
  /// trains OpenCV's detector on it. Throws InputError for an id added twice.
  void addObject(int obj_id, const Mesh& mesh);
  std::vector<int> objects() const;

  /// depth_mm: CV_16UC1 millimetres (0: no reading); camera: its intrinsics. Throws
  /// InputError for an empty or wrongly typed depth image or a bad camera.
  PpfResult detect(const cv::Mat& depth_mm, const Camera& camera) const;

  /// The training time of the objects added so far, milliseconds.
  double trainingMs() const { return training_ms_; }

 private:
  struct Model;
  PpfParams params_;
  std::vector<std::unique_ptr<Model>> models_;
  double training_ms_ = 0;
};

/// Points uniformly on a mesh's surface (area-weighted, deterministic for a seed) with unit
/// normals interpolated from the vertex normals (the face's normal for a mesh without vertex
/// normals): a CV_32FC1 matrix of count x 6 rows
/// (x y z nx ny nz), metres, object frame.
cv::Mat sampleMeshSurface(const Mesh& mesh, int count, unsigned seed = 1);

}  // namespace vkpose
