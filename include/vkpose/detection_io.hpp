#pragma once
// What `vkpose detect` writes: the detection JSON of DESIGN.md ("Data conventions"), which
// scripts rely on, and an overlay PNG a person can look at.
#include <string>

#include <opencv2/core.hpp>

#include "vkpose/detector.hpp"

namespace vkpose {

/// Where a result came from, for the JSON's header fields.
struct DetectionSource {
  std::string rgb, depth, device;
};

/// The detection JSON document: {"rgb", "depth", "device", "detections": [{"object", "score",
/// "bbox": [x, y, w, h], "R": [9, row-major], "t": [metres], "collision_rate", "icp_fitness",
/// "templates", ...}], "rejected": [the same, with "reason"], "timings_ms": {stage: ms}},
/// pretty-printed.
std::string detectionJson(const DetectionResult& result, const DetectionSource& source);

/// Writes `text` to `path`; InputError when the file exists and `overwrite` is false, or
/// when it cannot be written.
void writeTextFile(const std::string& path, const std::string& text, bool overwrite);

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

/// Writes an image (PNG); InputError when the file exists and `overwrite` is false, or when
/// it cannot be written.
void writeImage(const std::string& path, const cv::Mat& image, bool overwrite);

}  // namespace vkpose
