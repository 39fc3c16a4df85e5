#pragma once
// The detector facade: chains the stages (features and similarity on the GPU, clustering,
// cluster score, NMS, initial pose, refinement, verification) for several objects at once and
// records the time of each stage. It owns no algorithm of its own; every stage is callable
// alone (matcher.hpp, hypotheses.hpp, cluster_score.hpp, initial_pose.hpp, refine.hpp,
// verify.hpp).
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "vkpose/cluster_score.hpp"
#include "vkpose/hypotheses.hpp"
#include "vkpose/initial_pose.hpp"
#include "vkpose/matcher.hpp"
#include "vkpose/refine.hpp"
#include "vkpose/verify.hpp"
#include "vkpose/template_bank.hpp"

namespace vkpose {

struct DetectorParams {
  MatchParams match;
  ClusterParams cluster;
  ScoreParams score;
  NmsParams nms;
  /// Without stages 6-8 (estimate_poses false): hypotheses whose cluster score gamma is below
  /// this are dropped before NMS (a cluster on clutter, a template that fits the colour edges
  /// but not the depth).
  float min_score = 0.15f;
  /// With stages 6-8: hypotheses with gamma from this up go through NMS within their object,
  /// and the best pose_candidates_per_object of each object get a pose; verification, not
  /// gamma, then decides. On real Kinect depth at 1 m, gamma of a correct hypothesis can be as
  /// low as 0.13 (LM-O), and a cluttered object's best hypothesis can rank below hundreds of
  /// other objects' ones, so one global gamma cut and NMS across objects would lose it.
  float pose_min_score = 0.05f;
  int pose_candidates_per_object = 16;
  /// Stages 6-8 (initial pose, MLS + ICP, octree verification). false: stop after NMS and
  /// report the best template's pose, unverified.
  bool estimate_poses = true;
  InitialPoseParams initial_pose;
  RefineParams refine;
  VerifyParams verify;
  /// Two accepted poses whose object centres are closer than this fraction of the smaller
  /// diameter claim the same space: only the better one is kept (two clusters of one
  /// instance that NMS kept apart in the image converge to one place after ICP).
  float duplicate_fraction = 0.3f;
  unsigned threads = 0;  ///< CPU threads for the per-hypothesis stages (0: all cores)
};

/// Throws InputError naming the first bad value of any stage.
void validateDetectorParams(const DetectorParams& params);

/// One detected object instance.
struct Detection {
  int bank = 0;
  std::string object;         ///< the bank's object name
  /// gamma without stages 6-8; with them the verification score
  /// phi * (1 - see-through share) * silhouette support
  float score = 0.f;
  float gamma = 0.f;          ///< cluster score alpha * beta
  float alpha = 0.f, beta = 0.f;
  float x = 0.f, y = 0.f;     ///< image position of the object's centre
  cv::Rect2f bbox;            ///< pixels: the best template's object box
  Pose pose;                  ///< refined pose (or, without stages 6-8, the best template's)
  int templates = 0;          ///< members of the cluster
  int template_index = -1;    ///< the best template (within the bank)
  float similarity = 0.f;     ///< its LINEMOD similarity, percent
  // Stages 6-8; unset (verified false, collision_rate -1) when they did not run.
  bool verified = false;       ///< the refined pose passed verification
  float collision_rate = -1.f; ///< phi
  float see_through = 0.f;     ///< share of the visible model points the camera sees through
  float depth_fit = 0.f;       ///< share of the visible model points within tolerance of the scene depth
  float silhouette_support = 0.f;  ///< share of the outline with a depth step behind it
  double icp_fitness = 0;      ///< mean squared pair distance after ICP, m^2
  int icp_iterations = 0;
  int rotation_votes = 0;      ///< templates in the largest rotation group
  std::string rejection;       ///< why a hypothesis was rejected (empty when accepted)
};

/// Milliseconds per stage, in pipeline order.
using StageTimings = std::vector<std::pair<std::string, double>>;

struct DetectionResult {
  std::vector<Detection> detections;  ///< best score first
  std::vector<Detection> rejected;    ///< hypotheses that stages 6-8 rejected, with the reason
  StageTimings timings_ms;
  std::size_t matches = 0, hypotheses = 0, scored_hypotheses = 0;  ///< counts after stages 2, 3, 4
  std::vector<std::string> warnings;  ///< e.g. a bank trained for another focal length
};

class Detector {
 public:
  /// The banks must share the feature parameters (pyramid, modalities) of the first.
  Detector(GpuContext& ctx, std::vector<TemplateBank> banks, DetectorParams params = {});
  ~Detector();
  Detector(const Detector&) = delete;
  Detector& operator=(const Detector&) = delete;

  /// Throws InputError for a frame with no depth or a camera whose principal point lies
  /// outside it (the image size is the frame's).
  DetectionResult detect(const LinemodFrame& frame, const Camera& camera);
  /// detect() on each frame in turn (cameras[i] for frames[i]) with two frames in flight:
  /// once a frame's GPU stages are done, the next frame's stages 1-2 start on the GPU and run
  /// while this frame's CPU stages (poses, verification) do. The same results as detect()
  /// frame by frame; the features and similarity times are then the device's.
  std::vector<DetectionResult> detectSequence(const std::vector<LinemodFrame>& frames,
                                              const std::vector<Camera>& cameras);

  const std::vector<TemplateBank>& banks() const { return banks_; }
  const DetectorParams& params() const { return params_; }

 private:
  GpuContext& ctx_;
  std::vector<TemplateBank> banks_;
  DetectorParams params_;
  std::unique_ptr<LinemodMatcher> matcher_;
  std::unique_ptr<ClusterScorer> scorer_;
  std::vector<std::unique_ptr<MeshRenderer>> renderers_;  ///< one per bank, for stage 6

  const LinemodFrame* in_flight_ = nullptr;  ///< the frame whose stages 1-2 the matcher is running

  DetectionResult detectFrame(const LinemodFrame& frame, const Camera& camera, const LinemodFrame* next);
  void estimatePoses(const std::vector<Hypothesis>& hypotheses, const ScoreScene& scene, DetectionResult& result);
};

/// Checks a frame and its camera for detection and returns the camera with the frame's size
/// (scene_camera.json entries carry none). Throws InputError for a bad frame (validateFrame), a
/// bad camera, or a principal point outside the frame (intrinsics of another camera).
Camera frameCamera(const LinemodFrame& frame, const Camera& camera, const FeatureParams& features);

/// The pose a hypothesis's template implies: the template's rotation turned onto the viewing
/// ray through the hypothesis centre, at the template's distance moved by the member's mean
/// depth offset.
Pose templatePose(const Hypothesis& h, const MemberScore& s, const BankTemplate& t, const TemplateBank& bank,
                  const Camera& camera);

}  // namespace vkpose
