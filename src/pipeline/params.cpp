// The checks of every stage's parameters (include/vkpose/config.hpp), in one GPU-, PCL- and
// OctoMap-free file: the config file reader and its fuzz target link it without the stages.
#include <cmath>
#include <fstream>
#include <string>
#include <utility>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "pose/refine.hpp"
#include "vkpose/config.hpp"
#include "vkpose/error.hpp"

namespace vkpose {

void validateScoreParams(const ScoreParams& p) {
  auto positive = [](float v, const char* name) {
    if (!(v > 0.f) || !std::isfinite(v)) throw InputError(std::string("cluster score: ") + name + " must be positive");
  };
  positive(p.depth_unit_m, "depth unit");
  positive(p.depth_cap_m, "depth cap");
  positive(p.angle_unit_rad, "angle unit");
  positive(p.normal_max_jump_m, "normal depth jump");
  if (p.normal_step_px < 1 || p.normal_step_px > 16) throw InputError("cluster score: normal step must be 1..16 pixels");
  if (!(p.min_valid_fraction >= 0.f && p.min_valid_fraction <= 1.f))
    throw InputError("cluster score: minimum valid fraction must be in [0, 1]");
  if (p.top_members < 1) throw InputError("cluster score: top members must be at least 1");
  if (p.max_members < 0) throw InputError("cluster score: max members must be >= 0 (0: all)");
}

void validateInitialPoseParams(const InitialPoseParams& p) {
  if (p.small_part_starts < 1 || p.small_part_starts > 16)
    throw InputError(fmt::format("the small parts' starts must be 1 to 16, not {}", p.small_part_starts));
  if (p.resting_poses_starts < 1 || p.resting_poses_starts > 16)
    throw InputError(fmt::format("the starts of banks of several resting poses must be 1 to 16, not {}",
                                 p.resting_poses_starts));
  if (!(p.rotation_cluster_deg > 0.f && p.rotation_cluster_deg <= 180.f))
    throw InputError(fmt::format("the rotation cluster angle must be in (0, 180] degrees, not {}",
                                 p.rotation_cluster_deg));
  if (!(p.depth_band_fraction > 0.f && p.depth_band_fraction <= 10.f))
    throw InputError(fmt::format("the depth band must be in (0, 10] diameters, not {}", p.depth_band_fraction));
  if (!(p.crop_margin_fraction >= 0.f && p.crop_margin_fraction <= 10.f))
    throw InputError(fmt::format("the crop margin must be in [0, 10] object sizes, not {}", p.crop_margin_fraction));
}

void validateMls(float radius, int order, float seed_voxel) {
  if (!(radius > 0.f) || !std::isfinite(radius))
    throw InputError(fmt::format("MLS radius must be positive and finite, got {}", radius));
  if (order < 0) throw InputError(fmt::format("MLS polynomial order must be >= 0, got {}", order));
  if (!(seed_voxel >= 0.f) || !std::isfinite(seed_voxel))
    throw InputError(fmt::format("MLS seed voxel must be >= 0 and finite, got {}", seed_voxel));
}

void validateRefineParams(const RefineParams& p) {
  if (p.mls) validateMls(p.mls_radius, p.mls_polynomial_order, 0.f);
  if (!std::isfinite(p.voxel_size) || p.voxel_size < 0.f)
    throw InputError(fmt::format("voxel size must be >= 0 and finite, got {}", p.voxel_size));
  for (float f : {p.coarse_fraction, p.fine_fraction})
    if (!(f > 0.f && f <= 1.f)) throw InputError(fmt::format("ICP threshold fractions must lie in (0, 1], got {}", f));
  if (p.coarse_iterations < 0 || p.fine_iterations < 0)
    throw InputError(fmt::format("ICP iteration limits must be >= 0, got {} and {}", p.coarse_iterations,
                                 p.fine_iterations));
  if (p.mls_max_neighbours < 0 || p.coarse_max_points < 0)
    throw InputError(fmt::format("refine.mls_max_neighbours and refine.coarse_max_points must be >= 0 (0: all), got {} "
                                 "and {}",
                                 p.mls_max_neighbours, p.coarse_max_points));
  if (!(p.convergence_epsilon >= 0.0))
    throw InputError(fmt::format("ICP convergence epsilon must be >= 0, got {}", p.convergence_epsilon));
  if (!std::isfinite(p.fixed_max_correspondence_m) || p.fixed_max_correspondence_m < 0.f)
    throw InputError(fmt::format("fixed max correspondence distance must be >= 0, got {}",
                                 p.fixed_max_correspondence_m));
  for (const auto& [name, value] : {std::pair{"first_fit_share", p.first_fit_share},
                                    std::pair{"first_fit_contour_share", p.first_fit_contour_share},
                                    std::pair{"first_fit_silhouette_share", p.first_fit_silhouette_share},
                                    std::pair{"first_fit_pulled_see_through", p.first_fit_pulled_see_through}})
    if (!(value >= 0.f && value <= 1.f))
      throw InputError(fmt::format("refine.{} must be in [0, 1], not {}", name, value));
  if (p.first_fit_per_place < 0)
    throw InputError(fmt::format("refine.first_fit_per_place must be >= 0 (0: all), not {}", p.first_fit_per_place));
}

void validateVerifyParams(const VerifyParams& params) {
  if (!(params.resolution > 0.f) || !std::isfinite(params.resolution))
    throw InputError(fmt::format("octree resolution must be positive and finite, got {}", params.resolution));
  if (!(params.crop_margin >= 0.f) || !std::isfinite(params.crop_margin))
    throw InputError(fmt::format("verification crop margin must be >= 0 and finite, got {}", params.crop_margin));
  if (!std::isfinite(params.threshold))
    throw InputError(fmt::format("collision rate threshold must be finite, got {}", params.threshold));
  if (!(params.see_through_tolerance >= 0.f) || !std::isfinite(params.see_through_tolerance))
    throw InputError(fmt::format("see-through tolerance must be >= 0 metres, got {}", params.see_through_tolerance));
  if (!(params.max_see_through >= 0.f && params.max_see_through <= 1.f))
    throw InputError(fmt::format("the largest see-through share must be in [0, 1], got {}", params.max_see_through));
  if (!(params.silhouette_jump > 0.f) || !std::isfinite(params.silhouette_jump))
    throw InputError(fmt::format("the silhouette step must be > 0 metres, got {}", params.silhouette_jump));
  if (!(params.min_silhouette_support >= 0.f && params.min_silhouette_support <= 1.f))
    throw InputError(fmt::format("the silhouette support must be in [0, 1], got {}", params.min_silhouette_support));
  if (!(params.max_shared_support >= 0.f && params.max_shared_support <= 1.f))
    throw InputError(fmt::format("the shared support must be in [0, 1], got {}", params.max_shared_support));
  if (!(params.symmetry_margin >= 0.f && params.symmetry_margin <= 1.f))
    throw InputError(fmt::format("the symmetry margin must be in [0, 1], got {}", params.symmetry_margin));
  for (const float tolerance : {params.look_alike_tolerance, params.small_part_look_alike_tolerance})
    if (!(tolerance >= 0.f && tolerance <= 0.5f))
      throw InputError(fmt::format("the look-alike tolerance must be in [0, 0.5] of the diameter, got {}", tolerance));
  if (!(params.min_contour_edges >= 0.f && params.min_contour_edges <= 1.f))
    throw InputError(fmt::format("the contour edge share must be in [0, 1], got {}", params.min_contour_edges));
  if (!std::isfinite(params.second_try_min_collision))
    throw InputError(fmt::format("the second try's collision rate must be finite, got {}",
                                 params.second_try_min_collision));
  if (!(params.twin_distance_fraction >= 0.f && params.twin_distance_fraction <= 1.f))
    throw InputError(fmt::format("the twin distance must be in [0, 1] of the diameter, got {}",
                                 params.twin_distance_fraction));
  if (!(params.twin_angle_deg >= 0.f && params.twin_angle_deg <= 180.f))
    throw InputError(fmt::format("the twin angle must be in [0, 180] degrees, got {}", params.twin_angle_deg));
  if (!(params.hopeless_support_share >= 0.f && params.hopeless_support_share <= 1.f))
    throw InputError(fmt::format("the hopeless support share must be in [0, 1], got {}", params.hopeless_support_share));
  for (const float agreement : {params.min_colour_agreement, params.small_part_min_colour_agreement})
    if (!(agreement >= -1.f && agreement <= 1.f))
      throw InputError(fmt::format("the colour agreement must be in [-1, 1], got {}", agreement));
}

void validateSensorParams(const SensorParams& p) {
  if (!(p.axial_sigma_at_1m >= 0.f && p.axial_sigma_at_1m < 1.f) || !(p.quantization_m >= 0.f && p.quantization_m < 1.f))
    throw InputError(fmt::format("the sensor's noise at 1 m ({} m) and depth step ({} m) must be in [0, 1) metres",
                                 p.axial_sigma_at_1m, p.quantization_m));
}

namespace {
struct NamedSensor {
  const char* name;
  SensorParams params;
};
// Axial noise at 1 m from the sensors' depth models (Khoshelham and Elberink 2012 for the
// Kinect; the RealSense D435's is z^2 * subpixel / (focal * baseline) at 0.08 px, 640 px,
// 50 mm); every one writes millimetre depth images.
constexpr NamedSensor kSensors[] = {
    {"kinect", {0.0015f, 0.001f}},
    {"primesense", {0.0010f, 0.001f}},
    {"realsense-d435", {0.0025f, 0.001f}},
    {"ideal", {0.f, 0.f}},
};
}  // namespace

std::vector<std::string> sensorProfileNames() {
  std::vector<std::string> names;
  for (const auto& s : kSensors) names.emplace_back(s.name);
  return names;
}

SensorParams sensorProfile(const std::string& name_or_file) {
  for (const auto& s : kSensors)
    if (name_or_file == s.name) return s.params;
  std::ifstream in(name_or_file);
  if (!in) {
    std::string names;
    for (const auto& n : sensorProfileNames()) names += (names.empty() ? "" : ", ") + n;
    throw InputError(fmt::format("--sensor '{}' is neither a profile ({}) nor a readable JSON file", name_or_file, names));
  }
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(in);
  } catch (const nlohmann::json::exception& e) {
    throw InputError(fmt::format("{}: not a JSON sensor file ({})", name_or_file, e.what()));
  }
  SensorParams p;
  if (!j.is_object()) throw InputError(name_or_file + ": a sensor file is a JSON object");
  for (const auto& item : j.items()) {
    float* field = item.key() == "axial_sigma_at_1m" ? &p.axial_sigma_at_1m
                   : item.key() == "quantization_m"  ? &p.quantization_m
                                                     : nullptr;
    if (!field)
      throw InputError(fmt::format("{}: unknown key \"{}\" (axial_sigma_at_1m, quantization_m)", name_or_file, item.key()));
    if (!item.value().is_number())
      throw InputError(fmt::format("{}: {} must be a number of metres", name_or_file, item.key()));
    *field = item.value().get<float>();
  }
  validateSensorParams(p);
  return p;
}

void validateDetectorParams(const DetectorParams& p) {
  if (!(p.match.threshold > 0.f && p.match.threshold <= 100.f))
    throw InputError(fmt::format("the match threshold must be in (0, 100] percent, not {}", p.match.threshold));
  if (p.match.outside_response < 0 || p.match.outside_response > 4)
    throw InputError(fmt::format("the response of a feature outside the image must be 0..4, not {}",
                                 p.match.outside_response));
  if (p.cluster.position_step_px < 1 || p.cluster.min_templates < 1)
    throw InputError(fmt::format("the clustering cell ({} px) and the smallest cluster ({} templates) must be 1 or more",
                                 p.cluster.position_step_px, p.cluster.min_templates));
  if (!(p.nms.radius_px >= 0.f) || !(p.nms.radius_fraction > 0.f) || !(p.nms.small_part_radius_fraction > 0.f))
    throw InputError("the NMS radius must be 0 or more pixels and its fractions more than 0");
  if (!(p.nms.runner_up_share >= 0.f && p.nms.runner_up_share <= 1.f))
    throw InputError(fmt::format("the NMS runner-up share must be in [0, 1], not {}", p.nms.runner_up_share));
  if (!(p.nms.template_weight >= 0.f && p.nms.template_weight <= 4.f))
    throw InputError(fmt::format("the NMS template weight must be in [0, 4], not {}", p.nms.template_weight));
  validateScoreParams(p.score);
  if (!(p.min_score >= 0.f && p.min_score <= 1.f)) throw InputError("minimum score must be in [0, 1]");
  if (!(p.pose_min_score >= 0.f && p.pose_min_score <= 1.f)) throw InputError("minimum pose score must be in [0, 1]");
  if (p.pose_candidates_per_object < 1)
    throw InputError(fmt::format("pose candidates per object must be at least 1, not {}", p.pose_candidates_per_object));
  if (p.small_part_pose_candidates < 1)
    throw InputError(fmt::format("pose candidates per small part must be at least 1, not {}", p.small_part_pose_candidates));
  validateInitialPoseParams(p.initial_pose);
  validateRefineParams(p.refine);
  validateVerifyParams(p.verify);
  if (!(p.duplicate_fraction >= 0.f && p.duplicate_fraction <= 10.f))
    throw InputError(fmt::format("the duplicate distance must be in [0, 10] diameters, not {}", p.duplicate_fraction));
  validateSensorParams(p.sensor);
  const ColourOnlyParams& c = p.colour_only;
  if (c.candidates_per_object < 1)
    throw InputError(fmt::format("colour-only pose candidates per object must be at least 1, not {}",
                                 c.candidates_per_object));
  if (!(c.threshold > 0.f && c.threshold <= 100.f))
    throw InputError(fmt::format("the colour-only match threshold must be in (0, 100] percent, not {}", c.threshold));
  if (c.starts < 1 || c.starts > 16)
    throw InputError(fmt::format("colour-only rotation starts must be 1..16, not {}", c.starts));
  if (!(c.canny_low > 0.f && c.canny_high >= c.canny_low && c.canny_high <= 5000.f))
    throw InputError(fmt::format("colour-only Canny thresholds must satisfy 0 < low <= high <= 5000, not {} and {}",
                                 c.canny_low, c.canny_high));
  if (!(c.edge_tolerance_px > 0.f && c.edge_tolerance_px <= 20.f))
    throw InputError(fmt::format("the colour-only edge tolerance must be in (0, 20] pixels, not {}", c.edge_tolerance_px));
  if (!(c.min_contour_support >= 0.f && c.min_contour_support <= 1.f))
    throw InputError(fmt::format("the colour-only contour support must be in [0, 1], not {}", c.min_contour_support));
  if (!(c.min_colour_agreement >= -1.f && c.min_colour_agreement <= 1.f))
    throw InputError(fmt::format("the colour-only colour agreement must be in [-1, 1], not {}", c.min_colour_agreement));
}

}  // namespace vkpose
