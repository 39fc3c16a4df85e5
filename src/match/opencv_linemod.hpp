#pragma once
// Bridges to OpenCV's cv::linemod, the peer implementation vkpose is tested and benchmarked
// against: templates convert both ways, so both match the very same templates.
#include <opencv2/rgbd/linemod.hpp>

#include "match/features.hpp"
#include "match/matcher.hpp"
#include "vkpose/bank.hpp"

namespace vkpose {

/// OpenCV's LINEMOD detector with the modalities and T of `params` (defaults: OpenCV's).
cv::Ptr<cv::linemod::Detector> makeOpenCvDetector(const FeatureParams& params);

/// A cv::linemod template pyramid (level-major, modality-minor, as Detector stores it) as a
/// vkpose template. `modalities` lists the detector's modalities in order.
LinemodTemplate fromOpenCvTemplate(const std::vector<cv::linemod::Template>& pyramid,
                                   const std::vector<Modality>& modalities);

/// The inverse: for Detector::addSyntheticTemplate.
std::vector<cv::linemod::Template> toOpenCvTemplate(const LinemodTemplate& t, const std::vector<Modality>& modalities);

/// The modalities a FeatureParams switches on, in vkpose's order (colour, then depth).
std::vector<Modality> activeModalities(const FeatureParams& params);

/// OpenCV's match as a vkpose match (raw score left 0).
Match fromOpenCvMatch(const cv::linemod::Match& m);

/// Cuts LINEMOD templates from image regions with OpenCV's own feature extraction
/// (Detector::addTemplate with a rectangular mask). Regions where OpenCV finds too few
/// features are skipped. Returns the templates as vkpose templates, in the same order as
/// they were added to `detector` (class "bench").
std::vector<LinemodTemplate> extractOpenCvTemplates(cv::linemod::Detector& detector, const LinemodFrame& frame,
                                                    const std::vector<cv::Rect>& regions, const FeatureParams& params);

}  // namespace vkpose
