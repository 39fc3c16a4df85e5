#include "training/view_features.hpp"

#include <algorithm>

#include "gpu/batch.hpp"
#include "match/frame_features_gpu.hpp"
#include "vkpose/error.hpp"

namespace vkpose {

namespace {

/// Where each crop goes in its atlas: rows of crops ("shelves") left to right, every origin a
/// multiple of 2^levels so that each level's pyramid samples the crop's own pixels.
struct Placement {
  std::size_t atlas = 0;
  cv::Point origin;
};

struct AtlasPlan {
  std::vector<Placement> placements;
  std::vector<cv::Size> sizes;  // of each atlas
};

int roundUp(int v, int to) { return (v + to - 1) / to * to; }

AtlasPlan planAtlases(const std::vector<LinemodFrame>& crops, int align, int gap, std::size_t max_pixels) {
  int width = 2048;
  for (const auto& c : crops) width = std::max(width, roundUp(c.depth_mm.cols + 2 * gap, align));
  AtlasPlan plan;
  int x = gap, y = gap, shelf = 0;
  auto close = [&] { plan.sizes.emplace_back(width, roundUp(y + shelf + gap, align)); };
  for (const auto& c : crops) {
    const cv::Size s = c.depth_mm.size();
    if (x + s.width + gap > width) {  // next shelf
      y = roundUp(y + shelf + gap, align);
      x = gap;
      shelf = 0;
    }
    if (static_cast<std::size_t>(width) * static_cast<std::size_t>(y + s.height + gap) > max_pixels && y > gap) {
      close();  // next atlas
      x = gap;
      y = gap;
      shelf = 0;
    }
    plan.placements.push_back({plan.sizes.size(), {x, y}});
    x = roundUp(x + s.width + gap, align);
    shelf = std::max(shelf, s.height);
  }
  if (!crops.empty()) close();
  return plan;
}

}  // namespace

ViewQuantizer::ViewQuantizer(const GpuContext& ctx, const FeatureParams& params, std::size_t max_atlas_pixels)
    : params_(params),
      max_atlas_pixels_(max_atlas_pixels),
      batch_(std::make_unique<gpu::Batch>(ctx)),
      features_(std::make_unique<gpu::FrameFeatures>(ctx, params)) {}

ViewQuantizer::~ViewQuantizer() = default;

std::vector<QuantizedView> ViewQuantizer::quantize(const std::vector<LinemodFrame>& crops) {
  const std::size_t levels = params_.T.size();
  for (const auto& c : crops)
    if (c.bgr.type() != CV_8UC3 || c.depth_mm.type() != CV_16UC1 || c.bgr.size() != c.depth_mm.size())
      throw std::logic_error("ViewQuantizer: a crop needs CV_8UC3 colour and CV_16UC1 depth of one size");
  const AtlasPlan plan = planAtlases(crops, 1 << levels, kGap, max_atlas_pixels_);
  std::vector<QuantizedView> out(crops.size());
  for (std::size_t a = 0; a < plan.sizes.size(); ++a) {
    // The atlas images are kept from call to call (fresh pages cost more than zeroing).
    LinemodFrame& atlas = atlas_;
    atlas.bgr.create(plan.sizes[a], CV_8UC3);
    atlas.depth_mm.create(plan.sizes[a], CV_16UC1);
    atlas.bgr.setTo(0);
    atlas.depth_mm.setTo(0);
    for (std::size_t i = 0; i < crops.size(); ++i) {
      if (plan.placements[i].atlas != a) continue;
      const cv::Rect at(plan.placements[i].origin, crops[i].depth_mm.size());
      crops[i].bgr.copyTo(atlas.bgr(at));
      crops[i].depth_mm.copyTo(atlas.depth_mm(at));
    }
    features_->recordQuantization(*batch_, atlas, params_.use_colour);
    std::vector<QuantizedLevel> labels;
    std::vector<cv::Mat>& magnitudes = magnitudes_;
    features_->downloadLabels(*batch_, labels);
    if (params_.use_colour) features_->downloadMagnitudes(*batch_, magnitudes);
    batch_->submit();
    for (std::size_t i = 0; i < crops.size(); ++i) {
      if (plan.placements[i].atlas != a) continue;
      QuantizedView& q = out[i];
      q.colour.resize(levels);
      q.magnitude.resize(levels);
      q.depth.resize(levels);
      const cv::Point o = plan.placements[i].origin;
      for (std::size_t l = 0; l < levels; ++l) {
        const cv::Rect r(o.x >> l, o.y >> l, crops[i].depth_mm.cols >> l, crops[i].depth_mm.rows >> l);
        if (params_.use_colour) {
          q.colour[l] = labels[l].labels[0](r).clone();
          q.magnitude[l] = magnitudes[l](r).clone();
        }
        if (params_.use_depth) q.depth[l] = labels[l].labels[1](r).clone();
      }
    }
  }
  return out;
}

}  // namespace vkpose
