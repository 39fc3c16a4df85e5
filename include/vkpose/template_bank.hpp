#pragma once
// Training (DESIGN.md stage 0): templates rendered from a mesh, their LINEMOD features, the
// pose each was rendered at, and the depth/normal crops the cluster score compares; and the
// bank file that stores them.
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "vkpose/camera.hpp"
#include "vkpose/features.hpp"
#include "vkpose/gpu_context.hpp"
#include "vkpose/mesh.hpp"
#include "vkpose/render.hpp"
#include "vkpose/templates.hpp"
#include "vkpose/views.hpp"

namespace vkpose {

struct TrainingParams {
  ViewSamplingParams views;
  /// Quantization and pyramid, the same as detection uses (T = {5, 8} by default).
  FeatureParams features;
  /// Features per modality per pyramid level. LINEMOD: 63 (more are allowed: sums widen).
  int features_per_modality = 63;
  /// Colour features need a gradient magnitude above this (OpenCV's strong threshold: 55).
  float strong_threshold = 55.f;
  /// Focal lengths of the camera the bank is for: templates are scale-specific.
  Camera camera;
  /// The object looks the same under some rotation (evaluation uses ADI instead of ADD).
  bool symmetric = false;
};

/// Throws InputError naming the bad value.
void validateTrainingParams(const TrainingParams& params);

/// Depth and normals of a rendered template, sampled every `stride` pixels over the object's
/// box: cell (i, j) is template pixel (x0 + j * stride, y0 + i * stride) (level 0, relative
/// to the template's top-left corner; x0, y0 <= 0 when the object reaches past the features).
struct TemplateCrop {
  int x0 = 0, y0 = 0;
  int stride = 1;
  int cols = 0, rows = 0;
  std::vector<uint16_t> depth_01mm;  ///< depth in 0.1 mm units, 0 = not the object
  std::vector<int8_t> normals;       ///< 3 per cell: unit camera-frame normal * 127
};

/// Cells per side of a template crop, at most.
constexpr int kCropCells = 24;

struct BankTemplate {
  LinemodTemplate linemod;  ///< features per pyramid level
  Pose pose;                ///< object-to-camera pose the template was rendered at
  float distance = 0.f;     ///< training distance d, metres (camera to the object's centre)
  float inplane_deg = 0.f;
  int viewpoint = 0;
  /// Where the object's centre projects, in level-0 pixels from the template's top-left.
  float anchor_x = 0.f, anchor_y = 0.f;
  TemplateCrop crop;
};

/// Everything detection needs about one object.
struct TemplateBank {
  std::string object;        ///< the mesh file's stem
  uint64_t mesh_hash = 0;    ///< FNV-1a 64 of the mesh file
  float diameter = 0.f;      ///< metres
  bool symmetric = false;
  Eigen::Vector3f centre = Eigen::Vector3f::Zero();  ///< the point the cameras look at (object frame)
  /// The mesh the bank was trained from (metres): the pose stages render it and compare it
  /// with the scene, so a bank file is all that detection needs.
  Mesh mesh;
  TrainingParams params;
  std::vector<BankTemplate> templates;

  std::vector<LinemodTemplate> linemodTemplates() const;
};

/// Called after each batch of views: (views done, views in all).
using TrainingProgress = std::function<void(std::size_t, std::size_t)>;

/// Per-stage training times.
struct TrainingTimings {
  double render_ms = 0, features_ms = 0, total_ms = 0;
  std::size_t dropped = 0;  ///< views with too few features to make a template
};

/// Renders every view of `params.views` on the GPU and extracts LINEMOD features from each,
/// as LINEMOD selects them: colour gradients on the silhouette and strong inner edges
/// (5x5 non-maximum suppression, magnitude above the strong threshold), normals inside the
/// eroded mask (centres of uniform regions first), spread out over the object.
TemplateBank trainTemplates(const GpuContext& ctx, const Mesh& mesh, const TrainingParams& params,
                            const TrainingProgress& progress = {}, TrainingTimings* timings = nullptr);

/// The same for an explicit list of views (e.g. a subset of sampleViews()); views that differ
/// only in in-plane rotation must be consecutive to share a rendering.
TemplateBank trainTemplatesFromViews(const GpuContext& ctx, const Mesh& mesh, const TrainingParams& params,
                                     const std::vector<TrainingView>& views, const TrainingProgress& progress = {},
                                     TrainingTimings* timings = nullptr);

/// The square tile training renders into: the params' focal length (made square), the
/// object's centre at the tile's centre, big enough for the object from the nearest view.
Camera trainingCamera(const Mesh& mesh, const TrainingParams& params, const std::vector<TrainingView>& views);

/// The features of one rendering (tile pixels) as a template; `ok` false when a modality
/// that is on has fewer than 4 features at some level.
struct ExtractedTemplate {
  bool ok = false;
  LinemodTemplate linemod;
  int origin_x = 0, origin_y = 0;  ///< template top-left in the rendering, level-0 pixels
  cv::Rect object;                 ///< the object's bounding box in the rendering
};
ExtractedTemplate extractTemplate(const Rendering& rendering, const TrainingParams& params);

/// Bank files (.vkpb): a versioned header, the training parameters, all templates, and an
/// FNV-1a 64 checksum of everything before it.
constexpr uint32_t kBankVersion = 2;  // 2: the mesh is stored
void saveBank(const TemplateBank& bank, const std::string& path);
/// Throws InputError naming the file and the problem: missing, not a bank, another version,
/// truncated, or a checksum mismatch.
TemplateBank loadBank(const std::string& path);

}  // namespace vkpose
