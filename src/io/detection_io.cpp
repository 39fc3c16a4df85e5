// The detection JSON and the overlay PNG.
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>

#include <fmt/format.h>
#include <nlohmann/json.hpp>
#include <opencv2/imgproc.hpp>

#include "io/image_file.hpp"
#include "vkpose/bank.hpp"
#include "vkpose/detector.hpp"
#include "vkpose/device.hpp"
#include "vkpose/error.hpp"
#include "vkpose/geometry.hpp"

namespace vkpose {

namespace {
/// Rounded for people and diffs: 4 decimals for scores, 6 for metres.
double round(double v, int decimals) {
  const double s = std::pow(10.0, decimals);
  return std::round(v * s) / s;
}

/// Poses compared with a detection's: angle, axis, depth fit, colour, score (and the depth
/// residual in mm where it counted).
nlohmann::ordered_json alternativesJson(const std::vector<SymmetryAlternative>& alternatives, bool residual) {
  auto out = nlohmann::ordered_json::array();
  for (const auto& a : alternatives) {
    nlohmann::ordered_json alt = {{"angle_deg", round(a.angle_deg, 1)},
                                  {"axis", {round(a.axis.x(), 4), round(a.axis.y(), 4), round(a.axis.z(), 4)}},
                                  {"depth_fit", round(a.depth_fit, 4)}};
    if (residual) alt["depth_residual_mm"] = round(1e3 * a.depth_residual_m, 2);
    alt["colour"] = round(a.colour, 4);
    alt["score"] = round(a.score, 4);
    out.push_back(std::move(alt));
  }
  return out;
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


nlohmann::ordered_json detectionEntry(const Detection& d) {
  nlohmann::ordered_json j;
  j["object"] = d.object;
  j["score"] = round(d.score, 4);
  j["bbox"] = {round(d.bbox.x, 1), round(d.bbox.y, 1), round(d.bbox.width, 1), round(d.bbox.height, 1)};
  auto R = nlohmann::ordered_json::array();
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) R.push_back(round(d.pose.R(r, c), 6));
  j["R"] = R;
  j["t"] = {round(d.pose.t.x(), 6), round(d.pose.t.y(), 6), round(d.pose.t.z(), 6)};
  if (d.collision_rate >= 0.f) {
    j["gamma"] = round(d.gamma, 4);
    j["collision_rate"] = round(d.collision_rate, 4);
    j["see_through"] = round(d.see_through, 4);
    j["depth_fit"] = round(d.depth_fit, 4);
    j["silhouette_support"] = round(d.silhouette_support, 4);
    j["contour_edges"] = round(d.contour_edges, 4);
    if (std::isfinite(d.outline_on_edges)) j["outline_on_edges"] = round(d.outline_on_edges, 4);
    if (std::isfinite(d.silhouette_scale)) j["silhouette_scale"] = round(d.silhouette_scale, 4);
    j["colour_agreement"] = round(d.colour_agreement, 4);
    j["colour_measured"] = d.colour_measured;
    j["icp_fitness"] = d.icp_fitness;  // m^2: tiny numbers, kept at full precision
    j["icp_iterations"] = d.icp_iterations;
    j["rotation_votes"] = d.rotation_votes;
  } else if (d.colour_only) {  // fitted to the image's edges: no depth test ran
    j["colour_only"] = true;
    j["contour_edges"] = round(d.contour_edges, 4);
    j["explained_edges"] = round(d.explained_edges, 4);
    if (std::isfinite(d.plain_outline_edges)) j["plain_outline_edges"] = round(d.plain_outline_edges, 4);
    if (std::isfinite(d.region_contrast)) j["region_contrast"] = round(d.region_contrast, 4);
    j["colour_agreement"] = round(d.colour_agreement, 4);
    j["colour_measured"] = d.colour_measured;
    j["contour_iterations"] = d.icp_iterations;
    j["rotation_votes"] = d.rotation_votes;
  }
  j["verified"] = d.verified;
  j["templates"] = d.templates;
  j["alpha"] = round(d.alpha, 4);
  j["beta"] = round(d.beta, 4);
  j["centre"] = {round(d.x, 1), round(d.y, 1)};
  j["template"] = d.template_index;
  j["similarity"] = round(d.similarity, 2);
  if (!d.symmetry_alternatives.empty()) {
    // Which near-symmetric poses were compared and by how much the kept one won.
    j["symmetry"] = {{"alternatives", alternativesJson(d.symmetry_alternatives, false)},
                     {"chosen", d.symmetry_chosen},
                     {"margin", round(d.symmetry_margin, 4)},
                     {"compared", d.symmetry_compared}};
    j["ambiguous_symmetry"] = d.ambiguous_symmetry;
  }
  if (!d.look_alike_alternatives.empty())
    // The look-alike half-turns refit and compared (the kept pose first), and the margin.
    j["look_alike_turns"] = {{"alternatives", alternativesJson(d.look_alike_alternatives, true)},
                             {"chosen", d.look_alike_chosen},
                             {"margin", round(d.look_alike_margin, 4)}};
  if (!d.rejection.empty()) j["reason"] = d.rejection;
  return j;
}
}  // namespace

std::string detectionJson(const DetectionResult& result, const DetectionSource& source) {
  nlohmann::ordered_json doc;
  doc["rgb"] = source.rgb;
  doc["depth"] = source.depth;
  doc["device"] = source.device;
  auto dets = nlohmann::ordered_json::array();
  for (const Detection& d : result.detections) dets.push_back(detectionEntry(d));
  doc["detections"] = std::move(dets);
  auto rejected = nlohmann::ordered_json::array();
  for (const Detection& d : result.rejected) rejected.push_back(detectionEntry(d));
  doc["rejected"] = std::move(rejected);
  doc["counts"] = {{"matches", result.matches},
                   {"hypotheses", result.hypotheses},
                   {"scored", result.scored_hypotheses},
                   {"refined", result.refined_candidates},
                   {"rejected", result.rejected.size()},
                   {"detections", result.detections.size()},
                   {"match_pairs", result.match_pairs},
                   {"match_pairs_pruned", result.match_pairs_pruned},
                   {"match_pairs_skipped", result.match_pairs_skipped}};
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

std::vector<std::vector<cv::Point>> silhouette(const Mesh& mesh, const Pose& pose, const Camera& camera) {
  cv::Mat mask = cv::Mat::zeros(camera.height, camera.width, CV_8UC1);
  std::vector<cv::Point> projected(mesh.vertices.size());
  std::vector<bool> in_front(mesh.vertices.size());
  for (std::size_t i = 0; i < mesh.vertices.size(); ++i) {
    const Eigen::Vector3f c = pose.R * mesh.vertices[i] + pose.t;
    in_front[i] = c.z() > 1e-3f;
    if (!in_front[i]) continue;
    const Eigen::Vector2f uv = camera.project(c);
    // Clamped far outside the image: fillConvexPoly works in int and clips itself.
    projected[i] = {static_cast<int>(std::clamp(uv.x(), -1e5f, 1e5f)), static_cast<int>(std::clamp(uv.y(), -1e5f, 1e5f))};
  }
  for (const auto& f : mesh.faces) {
    if (!in_front[static_cast<std::size_t>(f[0])] || !in_front[static_cast<std::size_t>(f[1])] ||
        !in_front[static_cast<std::size_t>(f[2])])
      continue;
    const cv::Point tri[3] = {projected[static_cast<std::size_t>(f[0])], projected[static_cast<std::size_t>(f[1])],
                              projected[static_cast<std::size_t>(f[2])]};
    cv::fillConvexPoly(mask, tri, 3, cv::Scalar(255));
  }
  std::vector<std::vector<cv::Point>> contours;
  cv::findContours(mask, contours, cv::RETR_EXTERNAL, cv::CHAIN_APPROX_SIMPLE);
  return contours;
}

namespace {
void drawLabel(cv::Mat& out, const std::string& label, cv::Point org, const cv::Scalar& colour) {
  const int font = cv::FONT_HERSHEY_SIMPLEX;
  int baseline = 0;
  const cv::Size ts = cv::getTextSize(label, font, 0.4, 1, &baseline);
  org.x = std::clamp(org.x, 0, std::max(0, out.cols - ts.width - 2));
  org.y = std::max(ts.height + 2, org.y);
  cv::rectangle(out, org + cv::Point(-1, baseline), org + cv::Point(ts.width + 1, -ts.height - 2), colour, cv::FILLED);
  cv::putText(out, label, org, font, 0.4, cv::Scalar(0, 0, 0), 1, cv::LINE_AA);
}

/// Outline and axes for a posed detection, box and centre for a template-only one.
void drawDetection(cv::Mat& out, const Detection& d, const TemplateBank* bank, const Camera& camera,
                   const cv::Scalar& colour, const std::string& label) {
  const cv::Rect box(cvRound(d.bbox.x), cvRound(d.bbox.y), cvRound(d.bbox.width), cvRound(d.bbox.height));
  const bool posed = (d.collision_rate >= 0.f || d.colour_only) && bank && !bank->mesh.faces.empty();
  if (!posed) {
    cv::rectangle(out, box, colour, 2, cv::LINE_AA);
    cv::drawMarker(out, cv::Point(cvRound(d.x), cvRound(d.y)), colour, cv::MARKER_CROSS, 10, 2, cv::LINE_AA);
    drawLabel(out, label, {box.x, box.y - 3}, colour);
    return;
  }
  const auto contours = silhouette(bank->mesh, d.pose, camera);
  cv::drawContours(out, contours, -1, colour, 2, cv::LINE_AA);
  const Eigen::Vector3f o = d.pose.R * bank->centre + d.pose.t;
  const float length = 0.35f * bank->diameter;
  const cv::Scalar axis_colour[3] = {{40, 40, 255}, {40, 255, 40}, {255, 80, 40}};
  if (o.z() > 1e-3f) {
    const Eigen::Vector2f uo = camera.project(o);
    for (int a = 0; a < 3; ++a) {
      const Eigen::Vector3f e = o + length * d.pose.R.col(a);
      if (!(e.z() > 1e-3f)) continue;
      const Eigen::Vector2f ue = camera.project(e);
      cv::line(out, cv::Point(cvRound(uo.x()), cvRound(uo.y())), cv::Point(cvRound(ue.x()), cvRound(ue.y())),
               axis_colour[a], 2, cv::LINE_AA);
    }
  }
  drawLabel(out, label, {box.x, box.y - 3}, colour);
}
}  // namespace

namespace {

/// Depth in false colour (near red, far blue), no depth black, with its range written on it.
cv::Mat depthPanel(const cv::Mat& depth_mm) {
  CV_Assert(depth_mm.type() == CV_16UC1);
  const cv::Mat valid = depth_mm > 0;
  double lo = 0, hi = 0;
  cv::minMaxLoc(depth_mm, &lo, &hi, nullptr, nullptr, valid);
  if (hi <= lo) hi = lo + 1;
  cv::Mat scaled;
  depth_mm.convertTo(scaled, CV_8U, -255.0 / (hi - lo), 255.0 * hi / (hi - lo));
  cv::Mat out;
  cv::applyColorMap(scaled, out, cv::COLORMAP_TURBO);
  out.setTo(cv::Scalar(0, 0, 0), ~valid);
  out.convertTo(out, -1, 0.8, 0);
  cv::putText(out, fmt::format("depth {:.2f} m (red) to {:.2f} m (blue)", lo / 1000, hi / 1000),
              cv::Point(6, out.rows - 8), cv::FONT_HERSHEY_SIMPLEX, 0.45, cv::Scalar(255, 255, 255), 1, cv::LINE_AA);
  return out;
}

}  // namespace

cv::Mat drawDetections(const cv::Mat& bgr, const DetectionResult& result, const std::vector<TemplateBank>& banks,
                       const Camera& camera, const OverlayOptions& options) {
  CV_Assert(bgr.type() == CV_8UC3);
  if (!options.depth_mm.empty()) {
    if (options.depth_mm.size() != bgr.size() || options.depth_mm.type() != CV_16UC1)
      throw InputError("the overlay's depth panel needs a 16-bit depth image of the colour image's size");
    // The same drawing on the colour image and on the depth, side by side.
    OverlayOptions single = options;
    single.depth_mm = cv::Mat();
    cv::Mat colour = drawDetections(bgr, result, banks, camera, single), depth;
    single.legend = false;
    depth = drawDetectionsOn(depthPanel(options.depth_mm), result, banks, camera, single);
    cv::Mat both;
    cv::hconcat(colour, depth, both);
    return both;
  }
  cv::Mat out = bgr.clone();
  // Dim the image a little so the drawing stands out.
  out.convertTo(out, -1, 0.75, 0);
  return drawDetectionsOn(out, result, banks, camera, options);
}

cv::Mat drawDetectionsOn(cv::Mat out, const DetectionResult& result, const std::vector<TemplateBank>& banks,
                         const Camera& camera, const OverlayOptions& options) {
  auto bankOf = [&](const Detection& d) {
    return d.bank >= 0 && static_cast<std::size_t>(d.bank) < banks.size() ? &banks[static_cast<std::size_t>(d.bank)]
                                                                          : nullptr;
  };
  auto labelOf = [](std::size_t index, const Detection& d) {
    return d.collision_rate >= 0.f ? fmt::format("{} {} {:.2f} phi {:.2f}", index, d.object, d.score, d.collision_rate)
                                   : fmt::format("{} {} {:.2f}", index, d.object, d.score);
  };
  if (options.show_rejected)
    for (std::size_t i = 0; i < result.rejected.size(); ++i)
      drawDetection(out, result.rejected[i], bankOf(result.rejected[i]), camera, cv::Scalar(40, 40, 230),
                    "x " + labelOf(i + 1, result.rejected[i]));
  for (std::size_t i = 0; i < result.detections.size(); ++i) {
    const Detection& d = result.detections[i];
    drawDetection(out, d, bankOf(d), camera, objectColour(d.bank), labelOf(i + 1, d));
  }
  if (!options.legend) return out;
  // Legend: detections per object, and what the numbers mean.
  std::map<std::string, std::pair<int, int>> per_object;  // object -> (count, bank)
  for (const Detection& d : result.detections) {
    auto& e = per_object[d.object];
    ++e.first;
    e.second = d.bank;
  }
  const int font = cv::FONT_HERSHEY_SIMPLEX;
  int y = 16;
  cv::putText(out,
              fmt::format("{} detections (label: index, object, score, collision rate phi){}", result.detections.size(),
                          options.show_rejected ? fmt::format("; {} rejected in red", result.rejected.size()) : ""),
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
  std::string why;
  const bool ok = writeImageFile(path, image, why);
  if (!why.empty()) throw InputError("cannot write " + path + ": " + why);
  if (!ok) throw InputError("cannot write " + path + " (use a .png name in an existing folder)");
}

}  // namespace vkpose
