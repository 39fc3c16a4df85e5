#include <algorithm>
#include <bit>
#include <chrono>
#include <cmath>

#include <fmt/format.h>
#include <Eigen/Geometry>
#include <opencv2/imgproc.hpp>

#include "match/features.hpp"
#include "render/render.hpp"
#include "training/scattered.hpp"
#include "training/training.hpp"
#include "training/view_features.hpp"
#include "util/parallel.hpp"
#include "util/timing.hpp"
#include "vkpose/bank.hpp"
#include "vkpose/device.hpp"
#include "vkpose/error.hpp"
#include "vkpose/geometry.hpp"

namespace vkpose {

namespace {

/// Colour candidates: gradient labels on or next to the object (silhouette and inner edges)
/// whose magnitude is a 5x5 local maximum above the strong threshold.
std::vector<FeatureCandidate> colourCandidates(const cv::Mat& labels, const cv::Mat& magnitude_sq, const cv::Mat& mask,
                                        float strong_threshold) {
  cv::Mat region;
  cv::dilate(mask, region, cv::Mat());
  const float strong_sq = strong_threshold * strong_threshold;
  std::vector<FeatureCandidate> out;
  for (int y = 2; y < labels.rows - 2; ++y)
    for (int x = 2; x < labels.cols - 2; ++x) {
      const uint8_t label = labels.at<uint8_t>(y, x);
      const int32_t m = magnitude_sq.at<int32_t>(y, x);
      if (!label || !region.at<uint8_t>(y, x) || !(static_cast<float>(m) > strong_sq)) continue;
      bool is_max = true;
      // Strict maximum, ties going to the earlier pixel in raster order.
      for (int dy = -2; dy <= 2 && is_max; ++dy)
        for (int dx = -2; dx <= 2 && is_max; ++dx) {
          if (!dx && !dy) continue;
          const int32_t n = magnitude_sq.at<int32_t>(y + dy, x + dx);
          const bool earlier = dy < 0 || (dy == 0 && dx < 0);
          if (n > m || (n == m && earlier)) is_max = false;
        }
      if (is_max) out.push_back({x, y, static_cast<uint8_t>(std::countr_zero(label)), std::sqrt(static_cast<float>(m))});
    }
  return out;
}

/// Depth candidates: normal labels inside the mask eroded twice (away from the silhouette's
/// unreliable normals), scored by the distance to the nearest change of label, so features
/// sit in the middle of uniformly oriented surfaces.
std::vector<FeatureCandidate> depthCandidates(const cv::Mat& labels, const cv::Mat& mask) {
  cv::Mat region;
  cv::erode(mask, region, cv::Mat(), cv::Point(-1, -1), 2);
  cv::Mat uniform = cv::Mat::zeros(labels.size(), CV_8UC1);
  for (int y = 1; y < labels.rows - 1; ++y)
    for (int x = 1; x < labels.cols - 1; ++x) {
      const uint8_t l = labels.at<uint8_t>(y, x);
      if (!l || !region.at<uint8_t>(y, x)) continue;
      const bool same = labels.at<uint8_t>(y - 1, x) == l && labels.at<uint8_t>(y + 1, x) == l &&
                        labels.at<uint8_t>(y, x - 1) == l && labels.at<uint8_t>(y, x + 1) == l;
      uniform.at<uint8_t>(y, x) = same ? 255 : 0;
    }
  cv::Mat distance;
  cv::distanceTransform(uniform, distance, cv::DIST_L2, 3);
  std::vector<FeatureCandidate> out;
  for (int y = 0; y < labels.rows; ++y)
    for (int x = 0; x < labels.cols; ++x) {
      const uint8_t l = labels.at<uint8_t>(y, x);
      if (l && region.at<uint8_t>(y, x))
        out.push_back({x, y, static_cast<uint8_t>(std::countr_zero(l)), distance.at<float>(y, x)});
    }
  return out;
}

}  // namespace

cv::Rect featureCrop(const cv::Rect& object, cv::Size tile, std::size_t levels) {
  // The object's box plus a margin of background; its origin is a multiple of 2^levels so the
  // pyramid samples the same pixels as on the whole tile. Outside the object the tile is
  // zero (black, no depth), so the filters' replicated and reflected borders at the crop's
  // edge see the zeros the tile holds there, and every label and magnitude in the crop is
  // the tile's: the margin only has to keep the candidates' windows (the dilated mask and
  // its 5 x 5 maxima, 3 pixels of each level) inside the crop at every level.
  const int align = 1 << levels, margin = 8 << (levels - 1);
  const int x0 = std::max(0, (object.x - margin) / align * align), y0 = std::max(0, (object.y - margin) / align * align);
  const int x1 = std::min(tile.width, object.br().x + margin), y1 = std::min(tile.height, object.br().y + margin);
  return {x0, y0, x1 - x0, y1 - y0};
}

cv::Mat depthMillimetres(const cv::Mat& depth_m) {
  cv::Mat depth_mm;
  depth_m.convertTo(depth_mm, CV_16U, 1000.0);
  return depth_mm;
}

QuantizedView quantizeView(const Rendering& crop, const FeatureParams& fp) {
  const std::size_t levels = fp.T.size();
  QuantizedView q;
  q.colour.resize(levels);
  q.magnitude.resize(levels);
  q.depth.resize(levels);
  cv::Mat bgr = crop.bgr;
  for (std::size_t l = 0; l < levels; ++l) {
    if (fp.use_colour) {
      if (l > 0) bgr = pyrDownColour(bgr);
      q.colour[l] = quantizeColourGradients(bgr, fp.weak_threshold, &q.magnitude[l]);
    }
    if (fp.use_depth)
      q.depth[l] = l == 0 ? quantizeDepthNormals(depthMillimetres(crop.depth), fp.distance_threshold_mm,
                                                 fp.difference_threshold_mm)
                          : downsampleLabels(q.depth[l - 1]);
  }
  return q;
}

ExtractedTemplate selectFeatures(const QuantizedView& q, const cv::Mat& crop_mask, const cv::Rect& roi,
                                 const cv::Rect& object, const TrainingParams& params) {
  const FeatureParams& fp = params.features;
  const std::size_t levels = fp.T.size();
  const int x0 = roi.x, y0 = roi.y;
  cv::Mat mask = crop_mask;
  std::vector<std::vector<FeatureCandidate>> chosen[kModalityCount];
  for (auto& c : chosen) c.resize(levels);
  for (std::size_t l = 0; l < levels; ++l) {
    if (l > 0) mask = downsampleLabels(mask);  // the pixels the depth labels keep
    if (fp.use_colour)
      chosen[0][l] = selectScattered(colourCandidates(q.colour[l], q.magnitude[l], mask, params.strong_threshold),
                                     params.features_per_modality);
    if (fp.use_depth)
      chosen[1][l] = selectScattered(depthCandidates(q.depth[l], mask), params.features_per_modality);
  }
  ExtractedTemplate out;
  // A view whose depth shows too little of the object keeps its colour features alone when
  // they suffice: a screw's shank 3-5 pixels wide has no surface normals at the coarse level
  // (every view of a thin screw was dropped), but its outline has gradients all along.
  bool depth_starved = false;
  for (std::size_t l = 0; l < levels; ++l)
    depth_starved |= fp.use_colour && fp.use_depth && chosen[1][l].size() < 4 && chosen[0][l].size() >= 4;
  if (depth_starved)
    for (auto& level : chosen[1]) level.clear();
  // The template's box over all levels and modalities, in level-0 pixels (even origin, so
  // every level's origin is a whole pixel), as OpenCV's cropTemplates.
  int min_x = INT32_MAX, min_y = INT32_MAX, max_x = INT32_MIN, max_y = INT32_MIN;
  for (int m = 0; m < kModalityCount; ++m)
    for (std::size_t l = 0; l < levels; ++l) {
      const bool on = m == 0 ? fp.use_colour : fp.use_depth && !depth_starved;
      if (on && chosen[m][l].size() < 4) return out;  // too little of the object to match
      for (const auto& c : chosen[m][l]) {
        min_x = std::min(min_x, c.x << l);
        min_y = std::min(min_y, c.y << l);
        max_x = std::max(max_x, c.x << l);
        max_y = std::max(max_y, c.y << l);
      }
    }
  if (min_x == INT32_MAX) return out;
  min_x -= min_x % 2;
  min_y -= min_y % 2;
  out.linemod.levels.resize(levels);
  for (std::size_t l = 0; l < levels; ++l) {
    auto& level = out.linemod.levels[l];
    level.width = (max_x - min_x) >> l;
    level.height = (max_y - min_y) >> l;
    for (int m = 0; m < kModalityCount; ++m)
      for (const auto& c : chosen[m][l])
        level.features.push_back({c.x - (min_x >> l), c.y - (min_y >> l), c.bin, static_cast<Modality>(m)});
  }
  out.object = object;
  out.origin_x = min_x + x0;
  out.origin_y = min_y + y0;
  out.ok = true;
  return out;
}

ExtractedTemplate extractTemplate(const Rendering& full, const TrainingParams& params) {
  const cv::Rect object = cv::boundingRect(full.mask());
  if (object.empty()) return {};
  const cv::Rect roi = featureCrop(object, full.depth.size(), params.features.T.size());
  const Rendering crop{full.depth(roi), full.normals(roi), full.bgr(roi)};
  return selectFeatures(quantizeView(crop, params.features), crop.mask(), roi, object, params);
}

namespace {

/// The crop of the object's box `box`, positioned relative to the template's origin.
TemplateCrop cropRendering(const Rendering& r, const cv::Rect& box, int template_x, int template_y) {
  const int origin_x = box.x, origin_y = box.y, width = box.width - 1, height = box.height - 1;
  TemplateCrop crop;
  crop.x0 = origin_x - template_x;
  crop.y0 = origin_y - template_y;
  crop.stride = std::max(1, (std::max(width, height) + kCropCells - 1) / kCropCells);
  crop.cols = width / crop.stride + 1;
  crop.rows = height / crop.stride + 1;
  crop.depth_01mm.assign(static_cast<std::size_t>(crop.cols) * crop.rows, 0);
  crop.normals.assign(static_cast<std::size_t>(crop.cols) * crop.rows * 3, 0);
  for (int i = 0; i < crop.rows; ++i)
    for (int j = 0; j < crop.cols; ++j) {
      const int x = origin_x + j * crop.stride, y = origin_y + i * crop.stride;
      if (x < 0 || y < 0 || x >= r.depth.cols || y >= r.depth.rows) continue;
      const float z = r.depth.at<float>(y, x);
      if (!(z > 0.f)) continue;
      const std::size_t k = static_cast<std::size_t>(i) * crop.cols + j;
      crop.depth_01mm[k] = static_cast<uint16_t>(std::clamp(std::lround(z * 1e4f), 1l, 65535l));
      const cv::Vec3f n = r.normals.at<cv::Vec3f>(y, x);
      for (int c = 0; c < 3; ++c) crop.normals[3 * k + c] = static_cast<int8_t>(std::lround(std::clamp(n[c], -1.f, 1.f) * 127.f));
    }
  return crop;
}

}  // namespace

// The tile holds the object from every training view, with the object's centre at pixel
// (half, half), plus a margin for the feature filters.
Camera trainingCamera(const Mesh& mesh, const TrainingParams& params, const std::vector<TrainingView>& views) {
  float bound = 0.f;
  const Eigen::Vector3f centre = mesh.bboxCentre();
  for (const auto& v : mesh.vertices) bound = std::max(bound, (v - centre).norm());
  float nearest = views.front().distance;
  for (const auto& v : views) nearest = std::min(nearest, v.distance);
  if (!(nearest > 1.1f * bound))
    throw InputError(fmt::format("training distance {} m is too close for '{}' (it reaches {:.3f} m from its centre)",
                                 nearest, mesh.name, bound));
  const double f = 0.5 * (params.camera.fx + params.camera.fy);
  // Half-angle of the tangent cone around the bounding sphere, projected.
  const int half = static_cast<int>(std::ceil(f * bound / std::sqrt(nearest * nearest - bound * bound))) + 12;
  // Square pixels (the mean focal length) make in-plane rotations exact image rotations.
  Camera tile = params.camera;
  tile.fx = tile.fy = 0.5 * (params.camera.fx + params.camera.fy);
  tile.cx = tile.cy = half;
  tile.width = tile.height = 2 * half + 2;
  if (tile.width > 4096)
    throw InputError(fmt::format("'{}' would render {} pixels wide at {} m: train from further away", mesh.name,
                                 tile.width, nearest));
  return tile;
}

namespace {

using util::msSince;

/// Views differing only by in-plane rotation share one rendering: the GPU renders each
/// (viewpoint, distance) once and the rotations are image rotations of it (exact for a
/// pinhole camera with square pixels, up to nearest-neighbour resampling). `bases` are the
/// renderings' poses, `members[b]` the views (indices, in order) that turn rendering b.
struct RenderingGroups {
  std::vector<Pose> bases;
  std::vector<std::vector<std::size_t>> members;
};

RenderingGroups groupByRendering(const std::vector<TrainingView>& views) {
  RenderingGroups g;
  for (std::size_t i = 0; i < views.size(); ++i) {
    if (i == 0 || views[i].viewpoint != views[i - 1].viewpoint || views[i].distance != views[i - 1].distance) {
      const float a = -views[i].inplane_deg * static_cast<float>(CV_PI / 180.0);
      const Eigen::Matrix3f undo = Eigen::AngleAxisf(a, Eigen::Vector3f::UnitZ()).toRotationMatrix();
      g.bases.push_back({undo * views[i].R, undo * views[i].t});
      g.members.emplace_back();
    }
    g.members.back().push_back(i);
  }
  return g;
}

/// The templates of `view_ids` (views[view_ids[i]] turns renders[render_of[i]]): each view
/// turned in-plane and cut to its feature crop, quantized (on the GPU in one go when there is
/// a quantizer, one by one by the CPU reference otherwise) and its features selected. A view
/// that gives no template is left without levels.
std::vector<BankTemplate> chunkTemplates(const std::vector<Rendering>& renders, const std::vector<TrainingView>& views,
                                         const std::vector<std::size_t>& view_ids,
                                         const std::vector<std::size_t>& render_of, ViewQuantizer* quantizer,
                                         const TrainingParams& params, const Camera& tile) {
  const std::size_t m = view_ids.size();
  struct Cropped {
    Rendering crop;
    cv::Rect roi, object;
  };
  std::vector<Cropped> cropped(m);
  util::parallelFor(m, [&](std::size_t i) {
    const Rendering view = rotateInPlane(renders[render_of[i]], views[view_ids[i]].inplane_deg, tile.cx, tile.cy);
    Cropped& v = cropped[i];
    v.object = cv::boundingRect(view.mask());
    if (v.object.empty()) return;
    v.roi = featureCrop(v.object, view.depth.size(), params.features.T.size());
    v.crop = {view.depth(v.roi).clone(), view.normals(v.roi).clone(), view.bgr(v.roi).clone()};
  });
  std::vector<std::size_t> seen;
  for (std::size_t i = 0; i < m; ++i)
    if (!cropped[i].object.empty()) seen.push_back(i);
  std::vector<QuantizedView> quantized(m);
  if (quantizer) {
    std::vector<LinemodFrame> frames(seen.size());
    util::parallelFor(seen.size(), [&](std::size_t k) {
      frames[k] = {cropped[seen[k]].crop.bgr, depthMillimetres(cropped[seen[k]].crop.depth)};
    });
    auto q = quantizer->quantize(frames);
    for (std::size_t k = 0; k < seen.size(); ++k) quantized[seen[k]] = std::move(q[k]);
  } else {
    util::parallelFor(seen.size(), [&](std::size_t k) {
      quantized[seen[k]] = quantizeView(cropped[seen[k]].crop, params.features);
    });
  }
  std::vector<BankTemplate> made(m);  // no levels: the view gave no template
  util::parallelFor(m, [&](std::size_t i) {
    const Cropped& v = cropped[i];
    if (v.object.empty()) return;
    const ExtractedTemplate e = selectFeatures(quantized[i], v.crop.mask(), v.roi, v.object, params);
    if (!e.ok) return;
    const TrainingView& view = views[view_ids[i]];
    BankTemplate& bt = made[i];
    bt.linemod = e.linemod;
    bt.pose = {view.R, view.t};
    bt.distance = view.distance;
    bt.inplane_deg = view.inplane_deg;
    bt.viewpoint = view.viewpoint;
    bt.anchor_x = static_cast<float>(tile.cx - e.origin_x);
    bt.anchor_y = static_cast<float>(tile.cy - e.origin_y);
    // The object's box and the template's origin in crop pixels.
    bt.crop = cropRendering(v.crop, e.object - v.roi.tl(), e.origin_x - v.roi.x, e.origin_y - v.roi.y);
  });
  return made;
}

}  // namespace

TemplateBank trainTemplates(const GpuContext& ctx, const Mesh& mesh, const TrainingParams& params,
                            const TrainingProgress& progress, TrainingTimings* timings) {
  validateTrainingParams(params);
  return trainTemplatesFromViews(ctx, mesh, params, sampleViews(params.views, mesh.bboxCentre()), progress, timings);
}

TemplateBank trainTemplatesFromViews(const GpuContext& ctx, const Mesh& mesh, const TrainingParams& params,
                                     const std::vector<TrainingView>& views, const TrainingProgress& progress,
                                     TrainingTimings* timings) {
  return trainTemplatesWith(ctx, mesh, params, views, FeatureQuantization::gpu, progress, timings);
}

TemplateBank trainTemplatesWith(const GpuContext& ctx, const Mesh& mesh, const TrainingParams& params,
                                const std::vector<TrainingView>& views, FeatureQuantization quantization,
                                const TrainingProgress& progress, TrainingTimings* timings) {
  const auto t_start = std::chrono::steady_clock::now();
  validateTrainingParams(params);
  if (views.empty()) throw InputError("no training views");
  TemplateBank bank;
  bank.object = mesh.name;
  bank.mesh_hash = mesh.file_hash;
  bank.diameter = mesh.diameter;
  bank.symmetric = params.symmetric;
  bank.centre = mesh.bboxCentre();
  bank.mesh = mesh;
  bank.params = params;
  bank.near_symmetries = findNearSymmetries(mesh, params.near_symmetry_tolerance * mesh.diameter);
  const Camera tile = trainingCamera(mesh, params, views);
  const RenderingGroups groups = groupByRendering(views);
  MeshRenderer renderer(ctx, mesh);
  std::unique_ptr<ViewQuantizer> quantizer;
  if (quantization == FeatureQuantization::gpu) quantizer = std::make_unique<ViewQuantizer>(ctx, params.features);
  const std::size_t per_batch = std::min<std::size_t>(renderer.viewsPerBatch(tile), 32);
  // Views whose crops are held at once (each about 20 bytes per crop pixel).
  constexpr std::size_t kViewsPerChunk = 128;
  TrainingTimings t;
  std::size_t done = 0;
  for (std::size_t first = 0; first < groups.bases.size(); first += per_batch) {
    const std::size_t n = std::min(per_batch, groups.bases.size() - first);
    auto t0 = std::chrono::steady_clock::now();
    const auto renders =
        renderer.render(tile, std::vector<Pose>(groups.bases.begin() + first, groups.bases.begin() + first + n));
    t.render_ms += msSince(t0);
    t0 = std::chrono::steady_clock::now();
    std::vector<std::size_t> todo;
    std::vector<std::size_t> render_of;
    for (std::size_t b = first; b < first + n; ++b)
      for (std::size_t v : groups.members[b]) {
        todo.push_back(v);
        render_of.push_back(b - first);
      }
    for (std::size_t c = 0; c < todo.size(); c += kViewsPerChunk) {
      const std::size_t m = std::min(kViewsPerChunk, todo.size() - c);
      const auto part = [&](const std::vector<std::size_t>& all) {
        return std::vector<std::size_t>(all.begin() + static_cast<std::ptrdiff_t>(c),
                                        all.begin() + static_cast<std::ptrdiff_t>(c + m));
      };
      for (BankTemplate& made : chunkTemplates(renders, views, part(todo), part(render_of), quantizer.get(), params, tile)) {
        if (!made.linemod.levels.empty())
          bank.templates.push_back(std::move(made));
        else
          ++t.dropped;
      }
    }
    t.features_ms += msSince(t0);
    done += todo.size();
    if (progress) progress(done, views.size());
  }
  if (bank.templates.empty())
    throw InputError(fmt::format("no view of '{}' gave enough features for a template (is the mesh visible at {} m?)",
                                 mesh.name, params.views.radii.from));
  t.total_ms = msSince(t_start);
  if (timings) *timings = t;
  return bank;
}

}  // namespace vkpose
