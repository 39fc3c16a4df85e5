// The pick plan as JSON and drawn on the frame.
#include <fmt/format.h>
#include <nlohmann/json.hpp>
#include <opencv2/imgproc.hpp>

#include "vkpose/picking.hpp"

namespace vkpose {
namespace {
using nlohmann::json;

json vec(const Eigen::Vector3f& v) { return {v.x(), v.y(), v.z()}; }

json graspJson(const PlacedGrasp& g) {
  json R = json::array();
  for (int i = 0; i < 9; ++i) R.push_back(g.pose.R(i / 3, i % 3));
  json j = {{"name", g.name},
            {"priority", g.priority},
            {"R", R},
            {"t", vec(g.pose.t)},
            {"approach_point", vec(g.approach_point)},
            {"retreat_point", vec(g.retreat_point)},
            {"tilt_deg", g.tilt_deg},
            {"clearance_m", g.clearance_m}};
  if (g.suction_radius_m > 0.f) j["suction_radius_m"] = g.suction_radius_m;
  else j["opening_m"] = g.opening_m;
  return j;
}

cv::Point pixel(const Camera& camera, const Eigen::Vector3f& p) {
  const Eigen::Vector2f px = camera.project(p);
  return {static_cast<int>(std::lround(px.x())), static_cast<int>(std::lround(px.y()))};
}
}  // namespace

std::string pickPlanJson(const PickPlan& plan) {
  json grasps = json::array(), picks = json::array();
  for (const DetectionGrasps& d : plan.detections) {
    json valid = json::array(), refused = json::array();
    for (const PlacedGrasp& g : d.valid) valid.push_back(graspJson(g));
    for (const RefusedGrasp& r : d.refused) refused.push_back({{"name", r.name}, {"reason", r.reason}});
    grasps.push_back({{"valid", valid}, {"refused", refused}});
  }
  for (const Pick& p : plan.picks)
    picks.push_back({{"detection", p.detection},
                     {"grasp", graspJson(p.grasp)},
                     {"rank", p.rank},
                     {"score", p.score},
                     {"visible", p.visible},
                     {"height", p.height},
                     {"reach", p.reach},
                     {"free", p.free}});
  return json{{"grasps", grasps}, {"picks", picks}}.dump(2) + "\n";
}

void drawPicks(cv::Mat& bgr, const PickPlan& plan, const Camera& camera, int count) {
  const int n = std::min(count, static_cast<int>(plan.picks.size()));
  for (int k = n - 1; k >= 0; --k) {  // the first pick drawn last, on top
    const PlacedGrasp& g = plan.picks[static_cast<std::size_t>(k)].grasp;
    const cv::Scalar colour = k == 0 ? cv::Scalar(60, 220, 60) : cv::Scalar(0, 200, 255);
    const Eigen::Vector3f tcp = g.pose.t, x = g.pose.R.col(0), z = g.pose.R.col(2);
    if (g.approach_point.z() <= 0.f || tcp.z() <= 0.f) continue;
    cv::arrowedLine(bgr, pixel(camera, g.approach_point), pixel(camera, tcp), colour, 2, cv::LINE_AA, 0, 0.15);
    if (g.suction_radius_m > 0.f) {
      const int r = std::max(2, static_cast<int>(camera.fx * g.suction_radius_m / tcp.z()));
      cv::circle(bgr, pixel(camera, tcp), r, colour, 2, cv::LINE_AA);
    } else {
      // The jaws: two fingers at half the opening either side, reaching 2 cm back along z.
      const float finger = 0.02f;
      for (float side : {-1.f, 1.f}) {
        const Eigen::Vector3f tip = tcp + side * 0.5f * g.opening_m * x;
        cv::line(bgr, pixel(camera, tip), pixel(camera, tip - finger * z), colour, 3, cv::LINE_AA);
      }
      cv::line(bgr, pixel(camera, tcp - 0.5f * g.opening_m * x - finger * z),
               pixel(camera, tcp + 0.5f * g.opening_m * x - finger * z), colour, 2, cv::LINE_AA);
    }
    cv::putText(bgr, std::to_string(k + 1), pixel(camera, g.approach_point) + cv::Point(4, -4),
                cv::FONT_HERSHEY_SIMPLEX, 0.6, colour, 2, cv::LINE_AA);
  }
}

}  // namespace vkpose
