// Stage parameters in a JSON file (config.hpp).
#include "vkpose/config.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <limits>
#include <sstream>
#include <type_traits>
#include <variant>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "vkpose/error.hpp"

namespace vkpose {

using nlohmann::json;

namespace {

/// Stages 1-5 and the detector's own fields.
std::vector<ConfigField> hypothesisFields(DetectorParams& p) {
  return {
      {"match", "threshold", "LINEMOD similarity a match needs, percent", &p.match.threshold, aboveUpTo(0, 100), "--threshold"},
      {"match", "depth_pruning", "score templates only where the scene depth suits their distance", &p.match.depth_pruning},
      {"match", "outside_response", "response a template feature outside the image counts, 0..4", &p.match.outside_response, closed(0, 4)},
      {"match", "small_part_colour_alone", "parts under 10 cm, with a sensor.small_parts_unreliable: also match each template on its colour features alone", &p.match.small_part_colour_alone},
      {"cluster", "position_step_px", "clustering cell s_im, pixels", &p.cluster.position_step_px, closed(1, 512), "--cluster-step"},
      {"cluster", "min_templates", "smallest cluster tau_c, templates", &p.cluster.min_templates, atLeast(1), "--min-templates"},
      {"score", "depth_unit_m", "alpha = exp(-depth error / unit), metres", &p.score.depth_unit_m, above(0), "--depth-unit"},
      {"score", "depth_cap_m", "per-cell depth errors are truncated here, metres", &p.score.depth_cap_m, above(0)},
      {"score", "angle_unit_rad", "beta = exp(-mean normal angle / unit), radians", &p.score.angle_unit_rad, above(0), "--angle-unit"},
      {"score", "normal_step_px", "scene normals from neighbours this far apart, pixels", &p.score.normal_step_px, closed(1, 16)},
      {"score", "normal_max_jump_m", "neighbours further apart in depth give no normal, metres", &p.score.normal_max_jump_m, above(0)},
      {"score", "min_valid_fraction", "share of template cells with scene depth a member needs, 0..1", &p.score.min_valid_fraction, closed(0, 1)},
      {"score", "max_members", "cluster members scored, at most", &p.score.max_members, atLeast(0)},
      {"score", "top_members", "the cluster score is the mean of this many best members", &p.score.top_members, atLeast(1)},
      {"nms", "radius_px", "suppression radius, pixels (0: radius_fraction of the object's size)", &p.nms.radius_px, atLeast(0), "--nms-radius"},
      {"nms", "radius_fraction", "suppression radius, share of the larger projected diameter", &p.nms.radius_fraction, above(0)},
      {"nms", "template_weight", "parts under 10 cm: rank by gamma * (templates in the cluster)^w (0: gamma alone)", &p.nms.template_weight, closed(0, 4)},
      {"nms", "small_part_radius_fraction", "parts under 10 cm, with poses: suppression radius within the part, share of its projected diameter", &p.nms.small_part_radius_fraction, above(0)},
      {"nms", "runner_up_share", "objects of 10 cm and more, with poses: each survivor's best suppressed hypothesis of another view (for a bank of several resting poses, of each resting pose) also gets a pose when its gamma is at least this share of the survivor's (0: none)", &p.nms.runner_up_share, closed(0, 1)},
      {"nms", "resting_pose_runner_up_share", "the share a runner-up of another resting pose than the survivor's needs instead (banks of several resting poses)", &p.nms.resting_pose_runner_up_share, closed(0, 1)},
      {"nms", "across_objects", "suppress across objects too (without poses)", &p.nms.across_objects},
      {"detector", "estimate_poses", "run stages 6-8 (false: stop after NMS and report the best template's pose, unverified)", &p.estimate_poses, {}, "!--no-pose"},
      {"detector", "min_score", "without poses: smallest cluster score gamma, 0..1", &p.min_score, closed(0, 1), "--min-score"},
      {"detector", "pose_min_score", "smallest gamma a hypothesis needs for a pose, 0..1", &p.pose_min_score, closed(0, 1), "--pose-min-score"},
      {"detector", "pose_candidates_per_object", "hypotheses per object that get a pose", &p.pose_candidates_per_object, atLeast(1), "--pose-candidates"},
      {"detector", "small_part_pose_candidates", "hypotheses per part under 10 cm that get a pose", &p.small_part_pose_candidates, atLeast(1)},
      {"detector", "duplicate_fraction", "poses closer than this share of the diameter are one, 0..1", &p.duplicate_fraction, closed(0, 10)},
      {"detector", "threads", "CPU threads for the pose stages (0: every core; the results are the same for any count)", &p.threads, closed(0, 1024), "--threads"},
      {"colour_only", "threshold", "frames without depth: LINEMOD similarity a match needs, percent", &p.colour_only.threshold, aboveUpTo(0, 100)},
      {"colour_only", "candidates_per_object", "frames without depth: hypotheses per object that get a pose", &p.colour_only.candidates_per_object, atLeast(1)},
      {"colour_only", "starts", "frames without depth: rotation starts fitted per hypothesis, the best kept", &p.colour_only.starts, closed(1, 16)},
      {"colour_only", "canny_low", "frames without depth: Canny's low threshold (Sobel magnitude)", &p.colour_only.canny_low, aboveUpTo(0, 5000)},
      {"colour_only", "canny_high", "frames without depth: Canny's high threshold (Sobel magnitude)", &p.colour_only.canny_high, aboveUpTo(0, 5000)},
      {"colour_only", "edge_tolerance_px", "frames without depth: an outline point within this of an edge along it is supported, pixels", &p.colour_only.edge_tolerance_px, aboveUpTo(0, 20)},
      {"colour_only", "min_contour_support", "frames without depth: share of the outline a pose needs supported, 0..1", &p.colour_only.min_contour_support, closed(0, 1)},
      {"colour_only", "min_plain_outline_support", "frames without depth, meshes without colours over a surface of one colour: share of the outline alone a pose needs supported (0: off)", &p.colour_only.min_plain_outline_support, closed(0, 1)},
      {"colour_only", "min_uncoloured_mixed_support", "frames without depth, meshes without colours over several colours: share of all their edges a pose needs supported (at most colour_only.min_contour_support: off)", &p.colour_only.min_uncoloured_mixed_support, closed(0, 1)},
      {"colour_only", "min_colour_agreement", "frames without depth, meshes with colours: rendered and seen chromaticity must agree this much (-1: off)", &p.colour_only.min_colour_agreement, closed(-1, 1)},
      {"colour_only", "min_colourful_agreement", "the same for meshes whose colours vary (painted, printed)", &p.colour_only.min_colourful_agreement, closed(-1, 1)},
      {"colour_only", "try_turns", "frames without depth: each fitted pose also fitted from its object's look-alike turns, the best kept", &p.colour_only.try_turns},
      {"colour_only", "tilt_restart_deg", "frames without depth: each fitted pose also fitted tilted this much both ways about the camera's x and y axes, degrees (0: off)", &p.colour_only.tilt_restart_deg, closed(0, 90)},
      {"colour_only", "colour_turns", "frames without depth, meshes whose colours vary: each fitted pose also tried at the turns of a cube and eighth turns about its axes, and this many of the best fitted on (0: off)", &p.colour_only.colour_turns, closed(0, 35)},
      {"colour_only", "restart_rounds", "frames without depth: rounds of those restarts; after the first, the poses a restart improved are fitted again from their own turns and tilts (1: one round)", &p.colour_only.restart_rounds, closed(1, 10)},
      {"colour_only", "region_contrast_power", "frames without depth: the score is multiplied by the pose's region contrast (how well the frame's colours tell its mask from a band around it, 0..1) to this power (0: off)", &p.colour_only.region_contrast_power, closed(0, 20)},
  };
}

/// Stages 6 and 7.
std::vector<ConfigField> poseFields(DetectorParams& p) {
  return {
      {"initial_pose", "rotation_cluster_deg", "template rotations within this angle vote together, degrees", &p.initial_pose.rotation_cluster_deg, aboveUpTo(0, 180), "--rotation-cluster"},
      {"initial_pose", "second_start_by_fit",
       "also start from the rotation group that fits the scene's depth best, where it is not the largest", &p.initial_pose.second_start_by_fit},
      {"initial_pose", "small_part_starts",
       "parts under 10 cm: starts a hypothesis from this many of its largest rotation groups", &p.initial_pose.small_part_starts, closed(1, 16)},
      {"initial_pose", "resting_poses_starts",
       "banks trained in several resting poses (train --resting all): starts a hypothesis from this many of its largest "
       "rotation groups", &p.initial_pose.resting_poses_starts, closed(1, 16)},
      {"initial_pose", "range_along_ray",
       "convert the depth offset (a z-range) into the range along the viewing ray: objects off the optical axis", &p.initial_pose.range_along_ray},
      {"initial_pose", "depth_band_fraction", "scene points within this share of the diameter of the render count", &p.initial_pose.depth_band_fraction, aboveUpTo(0, 10)},
      {"initial_pose", "crop_margin_fraction", "scene crop margin, share of the diameter", &p.initial_pose.crop_margin_fraction, closed(0, 10)},
      {"initial_pose", "min_scene_points", "fewer scene points under the mask: rejected", &p.initial_pose.min_scene_points, atLeast(0)},
      {"refine", "mls", "smooth the scene crop with moving least squares", &p.refine.mls},
      {"refine", "mls_radius", "MLS search radius, metres", &p.refine.mls_radius, above(0)},
      {"refine", "mls_polynomial_order", "MLS fit: 2 quadric, 1 plane", &p.refine.mls_polynomial_order, atLeast(0)},
      {"refine", "mls_at_voxel_seeds", "MLS only at voxel-grid seeds (faster)", &p.refine.mls_at_voxel_seeds},
      {"refine", "mls_max_neighbours", "MLS fits at most this many neighbours (0: all)", &p.refine.mls_max_neighbours, atLeast(0)},
      {"refine", "voxel_size", "ICP voxel grid, metres", &p.refine.voxel_size, closed(0, 0.1), "--icp-voxel"},
      {"refine", "coarse_fraction", "coarse ICP correspondence distance, share of the diameter", &p.refine.coarse_fraction, aboveUpTo(0, 1)},
      {"refine", "fine_fraction", "fine ICP correspondence distance, share of the diameter", &p.refine.fine_fraction, aboveUpTo(0, 1)},
      {"refine", "coarse_iterations", "coarse ICP iteration limit (0: skip)", &p.refine.coarse_iterations, atLeast(0)},
      {"refine", "fine_iterations", "fine ICP iteration limit (0: skip)", &p.refine.fine_iterations, atLeast(0)},
      {"refine", "coarse_max_points", "model points the coarse ICP stage pairs, at most (0: all)", &p.refine.coarse_max_points, atLeast(0)},
      {"refine", "convergence_epsilon", "ICP stops when the transform changes less than this", &p.refine.convergence_epsilon, atLeast(0)},
      {"refine", "min_points", "fewer points after filtering: rejected", &p.refine.min_points, atLeast(0)},
      {"refine", "fixed_max_correspondence_m", "fixed ICP correspondence distance, metres (0: from the diameter)", &p.refine.fixed_max_correspondence_m, atLeast(0)},
      {"refine", "first_fit", "test every start after a cheap first fit (ICP on the raw crop, 250 model points) before MLS and ICP", &p.refine.first_fit},
      {"refine", "first_fit_share", "a start goes on when its first fit reaches this share of stage 8's collision and see-through limits", &p.refine.first_fit_share, closed(0, 1)},
      {"refine", "first_fit_contour_share",
       "a start goes on when its first fit's image-edge support reaches this share of verify.min_contour_edges", &p.refine.first_fit_contour_share, closed(0, 1)},
      {"refine", "first_fit_silhouette_share",
       "a start goes on when its first fit's silhouette support reaches this share of verify.min_silhouette_support", &p.refine.first_fit_silhouette_share, closed(0, 1)},
      {"refine", "first_fit_pulled_see_through",
       "a start above the collision limit seeing through this share at its first fit waits for stage 8's outline tests", &p.refine.first_fit_pulled_see_through, closed(0, 1)},
      {"refine", "first_fit_colour_margin",
       "a start whose mesh has colours goes on when its first fit's colours agree with the frame's to verify.min_colour_agreement less this", &p.refine.first_fit_colour_margin, closed(0, 2)},
      {"refine", "first_fit_twin_angle_deg",
       "a start whose first fit lies this close in angle (and verify.twin_distance_fraction in place) to a better one of its object stops", &p.refine.first_fit_twin_angle_deg, closed(0, 180)},
      {"refine", "first_fit_per_place",
       "starts of one object in one place after the first fit that go on (0: all)", &p.refine.first_fit_per_place, atLeast(0)},
  };
}

/// Stage 8 and the sensor.
std::vector<ConfigField> verifyFields(DetectorParams& p) {
  return {
      {"verify", "resolution", "octree leaf size, metres", &p.verify.resolution, aboveUpTo(0, 0.1), "--octree-resolution"},
      {"verify", "threshold", "collision rate phi a pose needs, 0..1", &p.verify.threshold, closed(0, 1), "--min-collision"},
      {"verify", "occlusion_credit",
       "phi counts over the model points the scene does not hide, at most this share of them hidden, 0..1 (0: off)", &p.verify.occlusion_credit, closed(0, 1)},
      {"verify", "crop_margin", "scene points within the model's box grown by this go in the octree, metres", &p.verify.crop_margin, atLeast(0)},
      {"verify", "see_through_tolerance", "scene depth this far behind the model sees through it, metres", &p.verify.see_through_tolerance, atLeast(0)},
      {"verify", "max_see_through", "largest share of model points the scene may see through, 0..1", &p.verify.max_see_through, closed(0, 1)},
      {"verify", "silhouette_jump", "a depth step this large marks the outline, metres", &p.verify.silhouette_jump, above(0)},
      {"verify", "min_silhouette_support", "share of the outline that must show a depth step, 0..1", &p.verify.min_silhouette_support, closed(0, 1)},
      {"verify", "min_contour_edges", "share of the visible outline that must meet an image edge, 0..1 (0: off)", &p.verify.min_contour_edges, closed(0, 1)},
      {"verify", "max_silhouette_scale", "reject when the scene's silhouette around the outline is more than this many times the model's (parts of 10 cm or more trained nearer than 0.5 m; 0: off)", &p.verify.max_silhouette_scale, closed(0, 2)},
      {"verify", "size_probe_margin", "reject when the model scaled by 1/1.15 or 1.15 explains the outline better than at its own size by more than this, 0..1 (1: off)", &p.verify.size_probe_margin, closed(0, 1)},
      {"verify", "max_shared_support", "share of its scene support a better detection may already claim, 0..1", &p.verify.max_shared_support, closed(0, 1)},
      {"verify", "resolve_symmetries", "render a pose's near-symmetric alternatives and keep the one colour and depth favour", &p.verify.resolve_symmetries},
      {"verify", "symmetry_margin", "score an alternative needs over ICP's pose to replace it; closer: ambiguous, 0..1", &p.verify.symmetry_margin, closed(0, 1)},
      {"verify", "look_alike_tolerance",
       "half-turns within this share of the diameter are refit and compared with the pose (0: off)", &p.verify.look_alike_tolerance, closed(0, 0.5)},
      {"verify", "small_part_look_alike_tolerance", "the same for parts under 10 cm (0.5: every half-turn)", &p.verify.small_part_look_alike_tolerance, closed(0, 0.5)},
      {"verify", "min_colour_agreement",
       "meshes with colours: the pose's rendered chromaticity must agree with the frame's this much (-1: off)", &p.verify.min_colour_agreement, closed(-1, 1)},
      {"verify", "small_part_min_colour_agreement", "the same for parts under 10 cm (their depth tests say less)", &p.verify.small_part_min_colour_agreement, closed(-1, 1)},
      {"verify", "min_outline_on_edges",
       "share of the visible outline whose nearest image edge lies within 1.5 px of it (0: off)", &p.verify.min_outline_on_edges, closed(0, 1)},
      {"verify", "small_turned_part_min_outline_on_edges",
       "the same for parts under 10 cm that are bodies of revolution (the larger of the two counts)", &p.verify.small_turned_part_min_outline_on_edges, closed(0, 1)},
      {"verify", "second_try_min_collision",
       "collision rate a pose needs when stage 6 had to move its start along the camera's axis (the larger of this and threshold)", &p.verify.second_try_min_collision, closed(0, 1)},
      {"verify", "twin_distance_fraction", "refined poses of one object this close (share of the diameter) ...", &p.verify.twin_distance_fraction, closed(0, 1)},
      {"verify", "twin_angle_deg", "... and turned less than this (degrees) are one candidate twice: the worse is dropped", &p.verify.twin_angle_deg, closed(0, 180)},
      {"verify", "hopeless_support_share",
       "a pose with less than this share of min_silhouette_support is not compared with its alternatives, 0..1", &p.verify.hopeless_support_share, closed(0, 1)},
      {"sensor", "axial_sigma_at_1m", "depth noise sigma(z) = this * z^2, metres at 1 m", &p.sensor.axial_sigma_at_1m, fromBelow(0, 1)},
      {"sensor", "quantization_m", "the depth images' step, metres", &p.sensor.quantization_m, fromBelow(0, 1)},
      {"sensor", "small_parts_unreliable", "parts under 10 cm show poorly in its depth (thin, shiny): small parts are also matched on colour alone", &p.sensor.small_parts_unreliable},
      {"detector", "scale_lengths", "lengths left at their defaults follow each object's size and the sensor's noise", &p.scale_lengths},
  };
}

}  // namespace

std::vector<ConfigField> configFields(DetectorParams& p) {
  std::vector<ConfigField> fields = hypothesisFields(p);
  for (auto part : {poseFields(p), verifyFields(p)}) fields.insert(fields.end(), part.begin(), part.end());
  return fields;
}

bool ValueRange::contains(double v) const {
  return (min_open ? v > min : v >= min) && (max_open ? v < max : v <= max);
}

std::string ValueRange::text() const {
  const bool low = min > -1e300, high = max < 1e300;
  if (low && high) return fmt::format("{}{:g}, {:g}{}", min_open ? "(" : "[", min, max, max_open ? ")" : "]");
  if (low) return fmt::format("{} {:g}", min_open ? ">" : ">=", min);
  if (high) return fmt::format("{} {:g}", max_open ? "<" : "<=", max);
  return "any";
}

void checkRanges(const DetectorParams& params, const std::string& section) {
  DetectorParams p = params;
  for (const ConfigField& f : configFields(p)) {
    if (!section.empty() && f.section != section) continue;
    std::visit(
        [&](auto* field) {
          if constexpr (!std::is_same_v<std::remove_pointer_t<decltype(field)>, bool>) {
            const double v = static_cast<double>(*field);
            if (!f.range.contains(v))
              throw InputError(fmt::format("{}.{} must be {}, not {}", f.section, f.key,
                                           f.range.min > -1e300 && f.range.max < 1e300 ? "in " + f.range.text()
                                                                                       : f.range.text(),
                                           *field));
          }
        },
        f.value);
  }
}

namespace {

json valueOf(const ConfigField& f) {
  return std::visit(
      [](auto* v) -> json {
        // A float printed shortest and read back as a double: 0.3f is written as 0.3, not
        // 0.30000001192092896.
        if constexpr (std::is_same_v<std::remove_pointer_t<decltype(v)>, float>) return std::stod(fmt::format("{}", *v));
        else return *v;
      },
      f.value);
}

std::string shown(const json& v) {
  if (v.is_number_float()) return fmt::format("{:g}", v.get<double>());
  return v.dump();
}

/// Sets the field from a JSON value of the right kind and range; the error names the key.
void assign(const ConfigField& f, const json& v, const std::string& where) {
  const std::string name = fmt::format("{}: {}.{}", where, f.section, f.key);
  std::visit(
      [&](auto* field) {
        using T = std::remove_pointer_t<decltype(field)>;
        if constexpr (std::is_same_v<T, bool>) {
          if (!v.is_boolean()) throw InputError(fmt::format("{} must be true or false, not {}", name, v.dump()));
          *field = v.get<bool>();
        } else if constexpr (std::is_floating_point_v<T>) {
          if (!v.is_number()) throw InputError(fmt::format("{} must be a number, not {}", name, v.dump()));
          const double d = v.get<double>();
          // Whether the field's type holds it once rounded, not whether d <= max: configJson
          // prints a float's shortest form, which for values near FLT_MAX reads back a little
          // above it (3.4028235e+38), and that must load again.
          if (!std::isfinite(d) || !std::isfinite(static_cast<T>(d)))
            throw InputError(fmt::format("{} must be a finite number, not {}", name, v.dump()));
          *field = static_cast<T>(d);
        } else {
          if (!v.is_number_integer()) throw InputError(fmt::format("{} must be a whole number, not {}", name, v.dump()));
          if (v.is_number_unsigned()) {
            const auto u = v.get<uint64_t>();
            if (u > static_cast<uint64_t>(std::numeric_limits<T>::max()))
              throw InputError(fmt::format("{} is too large: {}", name, v.dump()));
            *field = static_cast<T>(u);
          } else {
            const auto i = v.get<int64_t>();
            if (i < static_cast<int64_t>(std::numeric_limits<T>::min()) ||
                (i > 0 && static_cast<uint64_t>(i) > static_cast<uint64_t>(std::numeric_limits<T>::max())))
              throw InputError(fmt::format("{} is out of range: {}", name, v.dump()));
            *field = static_cast<T>(i);
          }
        }
      },
      f.value);
}

}  // namespace

std::string configJson(const DetectorParams& params) {
  DetectorParams p = params;
  // Sections and keys in pipeline order, as configFields lists them.
  nlohmann::ordered_json doc = nlohmann::ordered_json::object();
  for (const ConfigField& f : configFields(p))
    doc[f.section][f.key] = nlohmann::ordered_json::parse(valueOf(f).dump());
  return doc.dump(2) + "\n";
}

std::string configTable(const DetectorParams& params) {
  DetectorParams p = params;
  std::string out = fmt::format("{:<42} {:>10}  {:<13} {}\n", "parameter", "default", "range", "meaning");
  for (const ConfigField& f : configFields(p)) {
    const auto& scaled = scaledLengths();
    const bool follows = std::any_of(scaled.begin(), scaled.end(),
                                     [&](const ScaledLength& s) { return s.section == f.section && s.key == f.key; });
    const bool is_bool = std::holds_alternative<bool*>(f.value);
    out += fmt::format("{:<42} {:>10}  {:<13} {}{}{}\n", f.section + "." + f.key, shown(valueOf(f)),
                       is_bool ? "true, false" : f.range.text(), f.doc,
                       f.flag.empty()       ? ""
                       : f.flag[0] == '!' ? fmt::format(" (detect {}: false)", f.flag.substr(1))
                                          : fmt::format(" (detect {})", f.flag),
                       follows ? " [follows the object and the sensor]" : "");
  }
  out += fmt::format(
      "\nLengths that follow the object and the sensor (detector.scale_lengths true, the default): left at its\n"
      "default, each becomes min(default, max(default * diameter / {:g} m, k * noise(z))) for an object of that\n"
      "diameter whose pose candidate lies at distance z, noise(z) being the larger of the sensor's axial sigma\n"
      "(sensor.axial_sigma_at_1m * z^2) and its depth step (sensor.quantization_m). Objects of {:g} cm and more\n"
      "keep the defaults; smaller ones get lengths in proportion, never below k times what the sensor resolves.\n"
      "A length set to anything but its default (file or flag) is used as given. `vkpose -v detect` prints the\n"
      "values used per object.\n\n",
      kScaleReferenceDiameter, 100 * kScaleReferenceDiameter);
  out += fmt::format("{:<42} {:>4}  {}\n", "length", "k", "why it follows the object and the sensor");
  for (const ScaledLength& s : scaledLengths())
    out += fmt::format("{:<42} {:>4g}  {}\n", s.section + "." + s.key, s.noise_multiple, s.why);
  out += fmt::format(
      "\nParts smaller than {:g} cm are also ranked and started differently (their own settings; larger\n"
      "objects ignore them): nms.template_weight ranks their hypotheses by gamma x templates^w (a part a few\n"
      "LINEMOD cells across misaligns its depth crops, so gamma alone prefers bare floor),\n"
      "nms.small_part_radius_fraction narrows their NMS (the right view often sits in the cluster next to\n"
      "a look-alike one; verification removes the duplicates), detector.small_part_pose_candidates of them\n"
      "get a pose, initial_pose.small_part_starts starts each from that many rotation groups, and\n"
      "verify.small_part_look_alike_tolerance turns each accepted pose over and keeps the better fit, and\n"
      "verify.small_part_min_colour_agreement asks more of their colour (their depth tests say less).\n"
      "`vkpose train --resting auto` (the default) trains every resting pose of such a part.\n",
      100 * kSmallPartDiameterM);
  return out;
}

const std::vector<ScaledLength>& scaledLengths() {
  // The field accessors keep scaledForObject, which runs per pose candidate, off the
  // configFields() name lookup; Config.ScaledLengthsAreTheirConfigFields checks the names.
  static const std::vector<ScaledLength> lengths = {
      {"refine", "mls_radius", [](DetectorParams& p) -> float& { return p.refine.mls_radius; }, 5.f,
       "the smoothing neighbourhood must hold enough points, yet stay small against the object"},
      {"refine", "voxel_size", [](DetectorParams& p) -> float& { return p.refine.voxel_size; }, 2.f,
       "a 10 mm nut is 2-3 voxels of 4 mm; the grid must resolve the object's shape"},
      {"verify", "resolution", [](DetectorParams& p) -> float& { return p.verify.resolution; }, 2.f,
       "octree leaves: fine enough for the object's shape, coarse enough for the noise"},
      {"verify", "crop_margin", [](DetectorParams& p) -> float& { return p.verify.crop_margin; }, 5.f,
       "the scene around the model that the octree holds"},
      {"verify", "see_through_tolerance", [](DetectorParams& p) -> float& { return p.verify.see_through_tolerance; }, 5.f,
       "how far behind the model the scene must be to see through it"},
      {"verify", "silhouette_jump", [](DetectorParams& p) -> float& { return p.verify.silhouette_jump; }, 3.f,
       "a small part lying on a table shows a step of its own height, not 1 cm"},
  };
  return lengths;
}

float depthNoise(const SensorParams& sensor, float distance_m) {
  return std::max(sensor.axial_sigma_at_1m * distance_m * distance_m, sensor.quantization_m);
}

DetectorParams scaledForObject(const DetectorParams& params, float diameter_m, float distance_m) {
  DetectorParams out = params;
  if (!params.scale_lengths || !(diameter_m > 0.f)) return out;
  DetectorParams defaults;
  const float noise = depthNoise(params.sensor, std::max(distance_m, 0.f));
  for (const ScaledLength& s : scaledLengths()) {
    float& value = s.field(out);
    const float d = s.field(defaults);
    if (value != d) continue;  // set by the user
    value = std::min(d, std::max(d * diameter_m / kScaleReferenceDiameter, s.noise_multiple * noise));
  }
  return out;
}

std::string scaledLengthsReport(const DetectorParams& params, float diameter_m, float distance_m) {
  DetectorParams given = params, used = scaledForObject(params, diameter_m, distance_m), defaults;
  std::string out;
  for (const ScaledLength& s : scaledLengths()) {
    const float g = s.field(given), u = s.field(used), d = s.field(defaults);
    out += fmt::format("{}{}.{} {:.1f} mm{}", out.empty() ? "" : ", ", s.section, s.key, 1e3f * u,
                       g != d ? " (set)" : (u != d ? "" : " (default)"));
  }
  return out;
}

DetectorParams parseConfig(const std::string& text, const std::string& source, const DetectorParams& base) {
  json doc;
  try {
    doc = json::parse(text);
  } catch (const json::exception& e) {
    // parse_error for bad syntax, out_of_range for a number no double holds (1e400).
    throw InputError(fmt::format("{}: not a JSON config file ({})", source, e.what()));
  }
  if (!doc.is_object()) throw InputError(fmt::format("{}: a config file is a JSON object of sections", source));
  DetectorParams p = base;
  std::vector<ConfigField> fields = configFields(p);
  // Plain names, not structured bindings: clang 14 (the fuzz preset) cannot capture those in
  // the lambdas below.
  for (const auto& entry : doc.items()) {
    const std::string& section = entry.key();
    const json& keys = entry.value();
    if (std::none_of(fields.begin(), fields.end(), [&](const ConfigField& f) { return f.section == section; }))
      throw InputError(
          fmt::format("{}: unknown section \"{}\" (see vkpose config --print-defaults)", source, section));
    if (!keys.is_object())
      throw InputError(fmt::format("{}: \"{}\" must be an object of parameters", source, section));
    for (const auto& item : keys.items()) {
      const std::string& key = item.key();
      const json& value = item.value();
      const auto it = std::find_if(fields.begin(), fields.end(),
                                   [&](const ConfigField& f) { return f.section == section && f.key == key; });
      if (it == fields.end()) {
        std::string known;
        for (const ConfigField& f : fields)
          if (f.section == section) known += (known.empty() ? "" : ", ") + f.key;
        throw InputError(
            fmt::format("{}: unknown parameter {}.{} (known in {}: {})", source, section, key, section, known));
      }
      assign(*it, value, source);
    }
  }
  try {
    validateDetectorParams(p);
  } catch (const InputError& e) {
    throw InputError(fmt::format("{}: {}", source, e.what()));
  }
  return p;
}

DetectorParams loadConfig(const std::string& path, const DetectorParams& base) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(fmt::format("{}: no such config file", path));
  std::ostringstream text;
  text << in.rdbuf();
  return parseConfig(text.str(), path, base);
}

DetectorParams mergeConfig(const DetectorParams& defaults, const DetectorParams& from_file,
                           const DetectorParams& from_flags) {
  DetectorParams d = defaults, flags = from_flags, merged = from_file;
  const auto fd = configFields(d), ff = configFields(flags), fm = configFields(merged);
  for (std::size_t i = 0; i < fm.size(); ++i)
    if (valueOf(ff[i]) != valueOf(fd[i])) assign(fm[i], valueOf(ff[i]), "command line");
  return merged;
}

}  // namespace vkpose
