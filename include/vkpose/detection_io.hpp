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
/// "bbox": [x, y, w, h], "R": [9, row-major], "t": [metres], "templates", ...}],
/// "timings_ms": {stage: ms}}, pretty-printed.
std::string detectionJson(const DetectionResult& result, const DetectionSource& source);

/// Writes `text` to `path`; InputError when the file exists and `overwrite` is false, or
/// when it cannot be written.
void writeTextFile(const std::string& path, const std::string& text, bool overwrite);

/// The colour image with a box, a label (object and score) and the centre of every
/// detection, a colour per object, and a legend.
cv::Mat drawDetections(const cv::Mat& bgr, const DetectionResult& result);

/// Writes an image (PNG); InputError when the file exists and `overwrite` is false, or when
/// it cannot be written.
void writeImage(const std::string& path, const cv::Mat& image, bool overwrite);

}  // namespace vkpose
