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

#include "hypotheses/cluster_score.hpp"
#include "match/matcher.hpp"
#include "render/render.hpp"
#include "vkpose/bank.hpp"
#include "vkpose/detector.hpp"
#include "vkpose/evaluation.hpp"
#include "vkpose/geometry.hpp"

namespace vkpose {

// ---- LINEMOD alone ---------------------------------------------------------------------

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
