#include "match/opencv_linemod.hpp"

#include <algorithm>
#include <cstdlib>

#include "match/features.hpp"
#include "match/matcher.hpp"
#include "vkpose/bank.hpp"
#include "vkpose/error.hpp"

namespace vkpose {

std::vector<Modality> activeModalities(const FeatureParams& params) {
  std::vector<Modality> m;
  if (params.use_colour) m.push_back(Modality::ColourGradient);
  if (params.use_depth) m.push_back(Modality::DepthNormal);
  return m;
}

cv::Ptr<cv::linemod::Detector> makeOpenCvDetector(const FeatureParams& params) {
  std::vector<cv::Ptr<cv::linemod::Modality>> modalities;
  if (params.use_colour)
    modalities.push_back(cv::makePtr<cv::linemod::ColorGradient>(params.weak_threshold, 63, 55.0f));
  if (params.use_depth)
    modalities.push_back(cv::makePtr<cv::linemod::DepthNormal>(params.distance_threshold_mm,
                                                               params.difference_threshold_mm, 63, 2));
  return cv::makePtr<cv::linemod::Detector>(modalities, params.T);
}

LinemodTemplate fromOpenCvTemplate(const std::vector<cv::linemod::Template>& pyramid,
                                   const std::vector<Modality>& modalities) {
  const std::size_t nm = modalities.size();
  if (nm == 0 || pyramid.size() % nm != 0) throw InputError("OpenCV template pyramid does not fit the modalities");
  LinemodTemplate t;
  t.levels.resize(pyramid.size() / nm);
  for (std::size_t i = 0; i < pyramid.size(); ++i) {
    const auto& src = pyramid[i];
    auto& level = t.levels[static_cast<std::size_t>(src.pyramid_level)];
    level.width = src.width;
    level.height = src.height;
    for (const auto& f : src.features)
      level.features.push_back({f.x, f.y, static_cast<uint8_t>(f.label), modalities[i % nm]});
  }
  return t;
}

std::vector<cv::linemod::Template> toOpenCvTemplate(const LinemodTemplate& t, const std::vector<Modality>& modalities) {
  std::vector<cv::linemod::Template> out;
  for (std::size_t l = 0; l < t.levels.size(); ++l)
    for (Modality m : modalities) {
      cv::linemod::Template ct;
      ct.width = t.levels[l].width;
      ct.height = t.levels[l].height;
      ct.pyramid_level = static_cast<int>(l);
      for (const auto& f : t.levels[l].features)
        if (f.modality == m) ct.features.emplace_back(f.x, f.y, f.bin);
      out.push_back(ct);
    }
  return out;
}

Match fromOpenCvMatch(const cv::linemod::Match& m) {
  Match out;
  out.template_id = m.template_id;
  out.x = m.x;
  out.y = m.y;
  out.similarity = m.similarity;
  return out;
}

std::vector<LinemodTemplate> extractOpenCvTemplates(cv::linemod::Detector& detector, const LinemodFrame& frame,
                                                    const std::vector<cv::Rect>& regions, const FeatureParams& params) {
  std::vector<cv::Mat> sources;
  if (params.use_colour) sources.push_back(frame.bgr);
  if (params.use_depth) sources.push_back(frame.depth_mm);
  const auto modalities = activeModalities(params);
  std::vector<LinemodTemplate> out;
  for (const auto& region : regions) {
    const cv::Rect r = region & cv::Rect(0, 0, frame.bgr.cols, frame.bgr.rows);
    if (r.area() == 0) continue;
    cv::Mat mask = cv::Mat::zeros(frame.bgr.size(), CV_8UC1);
    mask(r).setTo(255);
    if (!frame.depth_mm.empty()) {
      // A rough object silhouette: the region's pixels within 60 mm of its median depth.
      std::vector<uint16_t> valid;
      for (int y = r.y; y < r.y + r.height; ++y)
        for (int x = r.x; x < r.x + r.width; ++x)
          if (uint16_t d = frame.depth_mm.at<uint16_t>(y, x)) valid.push_back(d);
      if (valid.size() > static_cast<std::size_t>(r.area() / 4)) {
        std::nth_element(valid.begin(), valid.begin() + static_cast<long>(valid.size() / 2), valid.end());
        const int median = valid[valid.size() / 2];
        for (int y = r.y; y < r.y + r.height; ++y)
          for (int x = r.x; x < r.x + r.width; ++x)
            if (std::abs(frame.depth_mm.at<uint16_t>(y, x) - median) > 60) mask.at<uint8_t>(y, x) = 0;
      }
    }
    const int id = detector.addTemplate(sources, "bench", mask);
    if (id < 0) continue;
    out.push_back(fromOpenCvTemplate(detector.getTemplates("bench", id), modalities));
  }
  return out;
}

}  // namespace vkpose
