// The detection JSON and the overlay PNG.
#include <filesystem>
#include <fstream>
#include <map>

#include <fmt/format.h>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "vkpose/detection_io.hpp"
#include "vkpose/error.hpp"

namespace vkpose {

namespace {
/// Rounded for people and diffs: 4 decimals for scores, 6 for metres.
double round(double v, int decimals) {
  const double s = std::pow(10.0, decimals);
  return std::round(v * s) / s;
}

void refuseOverwrite(const std::string& path, bool overwrite) {
  if (!overwrite && std::filesystem::exists(path))
    throw InputError(path + " exists; pass --force to overwrite it");
}

/// A colour per object, well apart in hue.
cv::Scalar objectColour(int bank) {
  static const cv::Scalar palette[] = {{60, 220, 60},  {40, 160, 255}, {255, 120, 40}, {220, 60, 220},
                                       {40, 230, 230}, {255, 220, 60}, {120, 60, 255}, {160, 255, 160}};
  return palette[static_cast<std::size_t>(bank) % std::size(palette)];
}
}  // namespace

std::string detectionJson(const DetectionResult& result, const DetectionSource& source) {
  nlohmann::ordered_json doc;
  doc["rgb"] = source.rgb;
  doc["depth"] = source.depth;
  doc["device"] = source.device;
  auto dets = nlohmann::ordered_json::array();
  for (const Detection& d : result.detections) {
    nlohmann::ordered_json j;
    j["object"] = d.object;
    j["score"] = round(d.score, 4);
    j["bbox"] = {round(d.bbox.x, 1), round(d.bbox.y, 1), round(d.bbox.width, 1), round(d.bbox.height, 1)};
    auto R = nlohmann::ordered_json::array();
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) R.push_back(round(d.pose.R(r, c), 6));
    j["R"] = R;
    j["t"] = {round(d.pose.t.x(), 6), round(d.pose.t.y(), 6), round(d.pose.t.z(), 6)};
    j["templates"] = d.templates;
    j["alpha"] = round(d.alpha, 4);
    j["beta"] = round(d.beta, 4);
    j["centre"] = {round(d.x, 1), round(d.y, 1)};
    j["template"] = d.template_index;
    j["similarity"] = round(d.similarity, 2);
    dets.push_back(std::move(j));
  }
  doc["detections"] = std::move(dets);
  doc["counts"] = {{"matches", result.matches},
                   {"hypotheses", result.hypotheses},
                   {"scored", result.scored_hypotheses},
                   {"detections", result.detections.size()}};
  nlohmann::ordered_json timings = nlohmann::ordered_json::object();
  for (const auto& [stage, ms] : result.timings_ms) timings[stage] = round(ms, 3);
  doc["timings_ms"] = std::move(timings);
  if (!result.warnings.empty()) doc["warnings"] = result.warnings;
  return doc.dump(2) + "\n";
}

void writeTextFile(const std::string& path, const std::string& text, bool overwrite) {
  refuseOverwrite(path, overwrite);
  std::ofstream out(path, std::ios::binary);
  if (!out || !(out << text) || !out.flush()) throw InputError("cannot write " + path);
}

cv::Mat drawDetections(const cv::Mat& bgr, const DetectionResult& result) {
  CV_Assert(bgr.type() == CV_8UC3);
  cv::Mat out = bgr.clone();
  // Dim the image a little so the boxes stand out.
  out.convertTo(out, -1, 0.75, 0);
  const int font = cv::FONT_HERSHEY_SIMPLEX;
  for (std::size_t i = 0; i < result.detections.size(); ++i) {
    const Detection& d = result.detections[i];
    const cv::Scalar colour = objectColour(d.bank);
    const cv::Rect box(cvRound(d.bbox.x), cvRound(d.bbox.y), cvRound(d.bbox.width), cvRound(d.bbox.height));
    cv::rectangle(out, box, colour, 2, cv::LINE_AA);
    cv::drawMarker(out, cv::Point(cvRound(d.x), cvRound(d.y)), colour, cv::MARKER_CROSS, 10, 2, cv::LINE_AA);
    const std::string label = fmt::format("{} {} {:.2f}", i + 1, d.object, d.score);
    int baseline = 0;
    const cv::Size ts = cv::getTextSize(label, font, 0.4, 1, &baseline);
    const cv::Point org(std::max(0, box.x), std::max(ts.height + 2, box.y - 3));
    cv::rectangle(out, org + cv::Point(-1, baseline), org + cv::Point(ts.width + 1, -ts.height - 2), colour, cv::FILLED);
    cv::putText(out, label, org, font, 0.4, cv::Scalar(0, 0, 0), 1, cv::LINE_AA);
  }
  // Legend: detections per object, and what the numbers mean.
  std::map<std::string, std::pair<int, int>> per_object;  // object -> (count, bank)
  for (const Detection& d : result.detections) {
    auto& e = per_object[d.object];
    ++e.first;
    e.second = d.bank;
  }
  int y = 16;
  cv::putText(out, fmt::format("{} detections (label: index, object, score gamma)", result.detections.size()),
              cv::Point(6, y), font, 0.45, cv::Scalar(255, 255, 255), 1, cv::LINE_AA);
  for (const auto& [object, e] : per_object) {
    y += 16;
    cv::rectangle(out, cv::Rect(6, y - 10, 10, 10), objectColour(e.second), cv::FILLED);
    cv::putText(out, fmt::format("{}: {}", object, e.first), cv::Point(20, y), font, 0.45, cv::Scalar(255, 255, 255), 1,
                cv::LINE_AA);
  }
  return out;
}

void writeImage(const std::string& path, const cv::Mat& image, bool overwrite) {
  refuseOverwrite(path, overwrite);
  bool ok = false;
  try {
    ok = cv::imwrite(path, image);
  } catch (const cv::Exception& e) {
    throw InputError("cannot write " + path + ": " + e.what());
  }
  if (!ok) throw InputError("cannot write " + path + " (use a .png name in an existing folder)");
}

}  // namespace vkpose
