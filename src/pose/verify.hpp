#pragma once
// Pose verification (docs/pipeline.md, stage 8; He, Rojas, Guan, section on hypothesis verification):
// the collision rate phi is the share of the posed model's visible points that fall into
// occupied cells of an octree built from the scene points. OctoMap stays inside
// src/pose/verify.cpp.
#include <cstddef>

#include <opencv2/core.hpp>

#include "geometry/point_cloud.hpp"
#include "vkpose/config.hpp"
#include "vkpose/geometry.hpp"

namespace vkpose {

struct VerifyResult {
  float collision_rate = 0;  ///< phi = hits / model_points, 0 when there are no model points
  std::size_t model_points = 0, hits = 0;  ///< finite model points; those in occupied cells
  std::size_t scene_points = 0;            ///< scene points inserted (after the crop)
  /// collision_rate > threshold, the paper's test; stage 8 leaves out the points the scene
  /// hides (unhiddenCollisionRate, pose/accept.hpp).
  bool accepted = false;
  double ms = 0;
};

/// How the scene depth at the pixels of camera-frame model points compares with theirs, as
/// shares of the points whose pixel has scene depth (all 0 when none has).
struct DepthAgreement {
  float fits = 0.f;          ///< within the tolerance
  float seen_through = 0.f;  ///< the scene lies farther: the camera sees through the model
  float occluded = 0.f;      ///< the scene lies nearer: something in front, or the model is sunk into a surface
  std::size_t with_depth = 0;
};
/// scene_depth_m: CV_32FC1 metres, 0 = none.
DepthAgreement depthAgreement(const PointCloud& model_points, const cv::Mat& scene_depth_m, const Camera& camera,
                              float tolerance);

/// The scene a posed model explains: indices (row-major, sorted, unique) of the `cell` x
/// `cell` pixel cells where a camera-frame model point projects onto scene depth within
/// `tolerance` of its own. Objects compete for these (VerifyParams::max_shared_support).
std::vector<int> supportCells(const PointCloud& model_points, const cv::Mat& scene_depth_m, const Camera& camera,
                              float tolerance, int cell = 4);

/// A point of the projected model's outline, the outline's outward unit normal there, and
/// the model's depth 3 px inside (0 where no model point projects near it).
struct OutlineSample {
  Eigen::Vector2f at, out;
  float model_z_in = 0.f;
};

/// The outline of the camera-frame model points projected into an image of `size`, one sample
/// a pixel (contours shorter than 8 px left out). The silhouette and contour tests read the
/// same samples: the detector computes them once a pose.
std::vector<OutlineSample> outlineSamples(const PointCloud& model_points, const Camera& camera, cv::Size size);

/// The share of a pose's points or outline samples that stage 8 counts when `hidden_share` of
/// them lie behind something nearer: the rest, but at least 1 - `occlusion_credit`
/// (VerifyParams::occlusion_credit; a pose sunk into a surface also looks hidden).
float unhiddenShare(float hidden_share, float occlusion_credit);

/// The silhouette test's share (see VerifyParams::silhouette_jump): the outline of the
/// camera-frame model points projected into the image, sampled every pixel; at each sample the
/// scene depth 3 px inside and 4 px outside along the outline's normal. Samples where either
/// has no depth or the outside is nearer (an occluder) are left out; the share is of the rest
/// whose outside lies at least `jump` farther. 0 when no sample is usable.
/// With `occlusion_credit` (VerifyParams::occlusion_credit) the samples where the scene inside
/// lies `jump` in front of the model (hidden) are left out of the count too, as far as that
/// share: steps / (usable x max(1 - hidden share, 1 - credit)), as the collision rate counts.
float silhouetteSupport(const PointCloud& model_points, const cv::Mat& scene_depth_m, const Camera& camera, float jump,
                        float occlusion_credit = 0.f);
float silhouetteSupport(const std::vector<OutlineSample>& outline, const cv::Mat& scene_depth_m, float jump,
                        float occlusion_credit = 0.f);
/// How large the scene's silhouette around a posed outline is, as a multiple of the model's:
/// along each outline sample's normal, the distance at which the scene's depth steps back by
/// `jump` (within `max_px`; samples behind something nearer, over holes or without a step are
/// left out), fitted by least squares as a constant margin, a scaling about the outline's centre
/// and a shift. A look-alike 10-20 % larger than the part, the model fitted into it, runs on past
/// the outline by (scale - 1) x its distance from the centre: about 1.1-1.2; the right pose
/// 1. NaN where fewer than 24 samples are usable, or where they cannot tell a scaling from a
/// margin or a shift (both ends of a bar hidden, or one).
float silhouetteScale(const std::vector<OutlineSample>& outline, const cv::Mat& scene_depth_m, float jump,
                      int max_px = 40);

/// The scene image's intensity gradients (Sobel of the lightly blurred grey image), computed
/// once a frame for contourEdgeSupport.
struct ImageEdges {
  cv::Mat dx, dy;  ///< CV_32FC1
};
ImageEdges imageEdges(const cv::Mat& bgr);

/// The contour test's share (see VerifyParams::min_contour_edges): of the projected model's
/// outline samples (as silhouetteSupport's), those within 2 px of an image edge of at least
/// `min_gradient` (Sobel units) running along the outline (gradient within 30 degrees of its
/// normal). Samples an occluder hides (the scene inside the outline nearer than the model,
/// or the scene outside nearer than inside, by `jump`) and samples on the image's border are
/// left out. A look-alike of the right size in the wrong
/// shape shows up here: a cup's handle must meet an edge where it is visible. 0 when no
/// sample is usable.
float contourEdgeSupport(const PointCloud& model_points, const ImageEdges& edges, const cv::Mat& scene_depth_m,
                         const Camera& camera, float jump, float min_gradient = 20.f);
/// How closely the outline lies on the image's edges: of the samples contourEdgeSupport uses,
/// the share whose nearest edge across the outline (within 6 px) lies within `tolerance_px` of
/// it. A right pose puts its outline on the object's own edges; a look-alike of about the same
/// size (a cylinder taken for a tapered cup) meets edges within contourEdgeSupport's 2 px
/// along most of its outline, but its nearest edges stray where the shapes differ.
float outlineOnEdges(const std::vector<OutlineSample>& outline, const ImageEdges& edges, const cv::Mat& scene_depth_m,
                     float jump, float min_gradient = 20.f, float tolerance_px = 1.5f);
float contourEdgeSupport(const std::vector<OutlineSample>& outline, const ImageEdges& edges,
                         const cv::Mat& scene_depth_m, float jump, float min_gradient = 20.f);

/// visible_model_points: camera-frame points of the model surface as the camera sees it at the
/// pose under test. scene_points: camera-frame scene points (a crop or the whole frame).
/// Non-finite points are ignored; empty inputs give phi = 0, rejected. Thread-safe.
VerifyResult verifyPose(const PointCloud& visible_model_points, const PointCloud& scene_points,
                        const VerifyParams& params = {});

/// verifyPose by the paper's octree itself: the scene's leaves inserted into an OctoMap
/// OcTree and each model point's leaf searched. The reference that verifyPose's key set
/// answers the same as (the parity test); about 1.2 ms more per call on a crop.
VerifyResult verifyPoseOctree(const PointCloud& visible_model_points, const PointCloud& scene_points,
                              const VerifyParams& params = {});

}  // namespace vkpose
