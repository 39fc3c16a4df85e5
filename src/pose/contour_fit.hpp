#pragma once
// Stage 7 without depth (docs/pipeline.md, colour only): the colour counterpart of ICP. The
// model's rendered outline is pulled onto the image's edges: a directional chamfer fit.
//   - The frame's edges (Canny of the lightly blurred grey image) are split by orientation
//     into 8 bins of 22.5 degrees (sign ignored); each bin's distance transform counts the
//     edges of its own and the two neighbouring bins, so an outline point is drawn only to
//     edges that run along it (EdgeDistanceMaps).
//   - The model is rendered at the pose; its outline (the mask's border, and the depth steps
//     inside it where one part of the model hides another) gives up to max_points 3D model
//     points, each with its orientation bin (contourPoints).
//   - Levenberg-Marquardt over the six degrees of freedom minimizes the sum of the points'
//     squared, truncated distances to their bin's edges; the truncation shrinks round by
//     round (coarse to fine) and the model is rendered again each round, as its outline
//     changes with the rotation (the caller renders: these are plain functions).
// Depth along the viewing ray is observed only through the outline's size, so it moves
// least; the 2D projection, which colour-only scoring (proj2d) measures, is what it fits.
#include <array>
#include <cstdint>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "render/render.hpp"
#include "vkpose/geometry.hpp"

namespace vkpose {

/// Per orientation bin, each pixel's distance (pixels, float, capped at kEdgeDistanceCap) to
/// the nearest edge pixel of that bin or either neighbour.
struct EdgeDistanceMaps {
  std::array<cv::Mat, 8> distance;  ///< CV_32FC1
  cv::Mat edges;                    ///< CV_8UC1: 0, or 1 + the edge's orientation bin
  cv::Size size() const { return edges.size(); }
};
constexpr float kEdgeDistanceCap = 64.f;

/// Orientation bin 0..7 (22.5 degrees each, sign ignored) of a gradient or normal (dx, dy).
int edgeOrientationBin(float dx, float dy);

/// The frame's directional edge maps: Canny (hysteresis low/high on the Sobel magnitude of the
/// 3x3-blurred image's strongest channel) and 8 distance transforms (none when `distances` is
/// false: the edges alone). bgr: CV_8UC3.
EdgeDistanceMaps edgeDistanceMaps(const cv::Mat& bgr, double canny_low = 40, double canny_high = 100,
                                  bool distances = true);

/// A point of the model's rendered outline.
struct ContourPoint {
  Eigen::Vector3f model;  ///< object frame, metres
  uint8_t bin = 0;        ///< orientation bin of the outline's normal in the image
};

/// The outline of a rendering of `pose` that covers `window` of `camera`'s image
/// (windowCamera): the mask's border, the inner depth steps of more than `inner_step_m` (the
/// nearer side) and, with `colour_edges`, the edges of the rendered colours inside, evenly
/// thinned to at most `max_points`. A mesh without colours renders shaded by a light at the
/// camera: its inner edges (a scanned part's ridges) are where that light puts them, not the
/// frame's light.
std::vector<ContourPoint> contourPoints(const Rendering& rendering, const Pose& pose, const Camera& camera,
                                        const cv::Rect& window, int max_points = 400, float inner_step_m = 0.01f,
                                        bool colour_edges = true);

struct ContourFitParams {
  /// Truncation of the distances per round, pixels, coarse to fine: a point farther from
  /// its edges than this counts as the cap (an occluded or unmatched stretch of outline).
  std::vector<float> truncation_px = {20.f, 10.f, 5.f, 3.f};
  int iterations = 10;  ///< Levenberg-Marquardt steps per round
};

struct ContourFit {
  Pose pose;
  float mean_distance_px = 0.f;  ///< mean truncated distance at the last round's truncation
  float inliers = 0.f;           ///< share of points within that truncation
  int iterations = 0;            ///< accepted steps
};

/// One round: Levenberg-Marquardt from `pose` on the points (object frame) against `maps`,
/// distances truncated at `truncation_px`. `camera` is the full frame's.
ContourFit fitContourRound(const std::vector<ContourPoint>& points, const Pose& pose, const Camera& camera,
                           const EdgeDistanceMaps& maps, float truncation_px, int iterations);

/// The converse of chamferSupport: of the frame's edge pixels under the rendering's mask
/// (`window` of the frame), the share within `tolerance_px` of one of the model's own edges
/// (outline, inner depth steps, edges of its colours). A pose laid on clutter covers edges the
/// model cannot explain. 1 when no edge lies under the mask.
float explainedEdgeShare(const Rendering& rendering, const cv::Rect& window, const EdgeDistanceMaps& maps,
                         float tolerance_px = 2.f, float inner_step_m = 0.01f);

/// The share of the points (at `pose`) that lie within `tolerance_px` of an edge of their bin,
/// of those that project into the image: a chamfer support, 0 when none projects in.
float chamferSupport(const std::vector<ContourPoint>& points, const Pose& pose, const Camera& camera,
                     const EdgeDistanceMaps& maps, float tolerance_px = 2.f);

}  // namespace vkpose
