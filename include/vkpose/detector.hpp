#pragma once
// The detector: chains the stages (features and similarity on the GPU, clustering, cluster
// score, NMS, initial pose, refinement, verification) for several objects at once and records
// the time of each stage (what it finds: detection.hpp), and what `vkpose detect` writes: the
// detection JSON (docs/formats.md), which scripts rely on, and an overlay PNG.
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include <opencv2/core.hpp>

#include "vkpose/bank.hpp"
#include "vkpose/config.hpp"
#include "vkpose/detection.hpp"
#include "vkpose/frame.hpp"
#include "vkpose/geometry.hpp"

namespace vkpose {

// Stage internals the Detector holds (src/).
class LinemodMatcher;
namespace match {
struct TemplateOrigins;
}
class ClusterScorer;
class MeshRenderer;
struct Hypothesis;
struct ScoreScene;
struct PoseObject;

class Detector {
 public:
  /// The banks must share the feature parameters (pyramid, modalities) of the first.
  Detector(GpuContext& ctx, std::vector<TemplateBank> banks, DetectorParams params = {});
  ~Detector();
  Detector(const Detector&) = delete;
  Detector& operator=(const Detector&) = delete;

  /// A frame without depth (depth_mm empty) runs colour-only: the colour modality alone,
  /// poses fitted to the image's edges (ColourOnlyParams); the banks need colour templates.
  /// Throws InputError for a depth image that is all zero or a camera whose principal point
  /// lies outside the frame (the image size is the frame's).
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
  /// Which bank template each of the matcher's templates matches for.
  std::unique_ptr<match::TemplateOrigins> template_origins_;
  std::unique_ptr<ClusterScorer> scorer_;
  std::vector<std::unique_ptr<MeshRenderer>> renderers_;  ///< one per bank, for stages 6-8 (made at first use)
  /// per bank: what stages 6-8 know of its object (src/pose/candidate.hpp): its renderer,
  /// bounding radius, whether its colours vary, its look-alike turns (found from the mesh
  /// when the detector is built)
  std::vector<PoseObject> objects_;

  /// Colour-only frames' matcher (made at the first such frame; src/pipeline/colour_only.hpp).
  struct ColourOnlyStages;
  std::unique_ptr<ColourOnlyStages> colour_only_;

  const LinemodFrame* in_flight_ = nullptr;  ///< the frame whose stages 1-2 the matcher is running

  DetectionResult detectFrame(const LinemodFrame& frame, const Camera& camera, const LinemodFrame* next);
  void estimatePoses(const std::vector<Hypothesis>& clusters, const ScoreScene& scene, const cv::Mat& frame_bgr,
                     DetectionResult& result);
  void attachRenderers();
  DetectionResult detectColourOnly(const LinemodFrame& frame, const Camera& camera);
};

// ---- detections to files --------------------------------------------------------------

/// Where a result came from, for the JSON's header fields.
struct DetectionSource {
  std::string rgb, depth, device;
};

/// The detection JSON document: {"rgb", "depth", "device", "detections": [{"object", "score",
/// "bbox": [x, y, w, h], "R": [9, row-major], "t": [metres], "collision_rate", "icp_fitness",
/// "templates", ...}], "rejected": [the same, with "reason"], "timings_ms": {stage: ms}},
/// pretty-printed.
std::string detectionJson(const DetectionResult& result, const DetectionSource& source);

struct OverlayOptions {
  bool show_rejected = false;  ///< also draw the hypotheses stages 6-8 rejected, in red
  bool legend = true;          ///< the counts per object and what the label numbers mean
  /// When set (16-bit, millimetres, the colour image's size): the depth in false colour with
  /// the same drawing, to the right of the colour image.
  cv::Mat depth_mm;
};

/// The colour image with every detection drawn in its object's colour: for a refined pose the
/// projected model outline and its axes (x red, y green, z blue), otherwise the template's box
/// and centre; a label (index, object, score, collision rate) and a legend. `banks` and
/// `camera` are the detector's (the meshes and the intrinsics the poses refer to).
cv::Mat drawDetections(const cv::Mat& bgr, const DetectionResult& result, const std::vector<TemplateBank>& banks,
                       const Camera& camera, const OverlayOptions& options = {});

/// drawDetections onto an image of the frame's size that the caller prepared (e.g. a depth
/// rendering), in place; returns it.
cv::Mat drawDetectionsOn(cv::Mat image, const DetectionResult& result, const std::vector<TemplateBank>& banks,
                         const Camera& camera, const OverlayOptions& options = {});

/// The outer contours of a mesh projected at `pose`, in pixels (its silhouette; no depth test
/// is needed for that).
std::vector<std::vector<cv::Point>> silhouette(const Mesh& mesh, const Pose& pose, const Camera& camera);

}  // namespace vkpose
