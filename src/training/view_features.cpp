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
  std::size_t pixels = 0;       // of all atlases together
};

int roundUp(int v, int to) { return (v + to - 1) / to * to; }

/// The crops in `order` onto shelves of atlases `width` pixels wide.
AtlasPlan packShelves(const std::vector<LinemodFrame>& crops, const std::vector<std::size_t>& order, int width,
                      int align, int gap, std::size_t max_pixels) {
  AtlasPlan plan;
  plan.placements.resize(crops.size());
  int x = gap, y = gap, shelf = 0;
  auto close = [&] {
    plan.sizes.emplace_back(width, roundUp(y + shelf + gap, align));
    plan.pixels += plan.sizes.back().area();
  };
  for (std::size_t i : order) {
    const cv::Size s = crops[i].depth_mm.size();
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
    plan.placements[i] = {plan.sizes.size(), {x, y}};
    x = roundUp(x + s.width + gap, align);
    shelf = std::max(shelf, s.height);
  }
  if (!crops.empty()) close();
  return plan;
}

/// Tallest crops first, so that a shelf's crops are of about its height, at the atlas width
/// that leaves the fewest pixels over: every atlas pixel costs the feature kernels the same,
/// crop or gap (a 2,048-pixel atlas of training's crops in view order was 69 % crops).
AtlasPlan planAtlases(const std::vector<LinemodFrame>& crops, int align, int gap, std::size_t max_pixels) {
  std::vector<std::size_t> order(crops.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    return crops[a].depth_mm.rows > crops[b].depth_mm.rows;
  });
  int narrowest = 0;
  for (const auto& c : crops) narrowest = std::max(narrowest, roundUp(c.depth_mm.cols + 2 * gap, align));
  // Widths from 1,024 pixels (no atlas much taller than wide) to 4,096, in steps that keep
  // the alignment.
  const int step = roundUp(64, align), widest = std::max(narrowest, 4096);
  AtlasPlan best;
  for (int width = std::max(narrowest, roundUp(1024, align)); width <= widest; width += step) {
    AtlasPlan plan = packShelves(crops, order, width, align, gap, max_pixels);
    if (best.sizes.empty() || plan.pixels < best.pixels) best = std::move(plan);
  }
  return best;
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
