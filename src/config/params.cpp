// The checks of every stage's parameters (include/vkpose/config.hpp): each field's range from
// the one parameter table (config_io.cpp), the few checks that relate two fields, and the
// sensor profiles. GPU-, PCL- and OctoMap-free: the config file reader and its fuzz target
// link it without the stages.
#include <cmath>
#include <fstream>
#include <string>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "vkpose/config.hpp"
#include "vkpose/error.hpp"

namespace vkpose {

namespace {
/// Defaults with one stage's parameters replaced: a stage checks its own section's ranges.
template <class Section>
DetectorParams withSection(Section DetectorParams::*member, const Section& section) {
  DetectorParams d;
  d.*member = section;
  return d;
}
}  // namespace

void validateScoreParams(const ScoreParams& p) { checkRanges(withSection(&DetectorParams::score, p), "score"); }

void validateInitialPoseParams(const InitialPoseParams& p) {
  checkRanges(withSection(&DetectorParams::initial_pose, p), "initial_pose");
}

void validateRefineParams(const RefineParams& p) { checkRanges(withSection(&DetectorParams::refine, p), "refine"); }

void validateVerifyParams(const VerifyParams& p) { checkRanges(withSection(&DetectorParams::verify, p), "verify"); }

void validateSensorParams(const SensorParams& p) { checkRanges(withSection(&DetectorParams::sensor, p), "sensor"); }

namespace {
struct NamedSensor {
  const char* name;
  SensorParams params;
};
// Axial noise at 1 m from the sensors' depth models (Khoshelham and Elberink 2012 for the
// Kinect; the RealSense D435's is z^2 * subpixel / (focal * baseline) at 0.08 px, 640 px,
// 50 mm; the close-range D415-class stereo camera's at 0.08 px, 720 px, 55 mm); every one
// writes millimetre depth images. synth adds the close-range camera's other effects
// (closeRangeNoise, synth.hpp).
constexpr NamedSensor kSensors[] = {
    {"kinect", {0.0015f, 0.001f, false}},
    {"primesense", {0.0010f, 0.001f, false}},
    {"realsense-d435", {0.0025f, 0.001f, false}},
    {"close-range", {0.0020f, 0.001f, true}},
    {"ideal", {0.f, 0.f, false}},
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
    if (item.key() == "small_parts_unreliable") {
      if (!item.value().is_boolean())
        throw InputError(fmt::format("{}: small_parts_unreliable must be true or false", name_or_file));
      p.small_parts_unreliable = item.value().get<bool>();
      continue;
    }
    float* field = item.key() == "axial_sigma_at_1m" ? &p.axial_sigma_at_1m
                   : item.key() == "quantization_m"  ? &p.quantization_m
                                                     : nullptr;
    if (!field)
      throw InputError(fmt::format("{}: unknown key \"{}\" (axial_sigma_at_1m, quantization_m, small_parts_unreliable)",
                                   name_or_file, item.key()));
    if (!item.value().is_number())
      throw InputError(fmt::format("{}: {} must be a number of metres", name_or_file, item.key()));
    *field = item.value().get<float>();
  }
  validateSensorParams(p);
  return p;
}

void validateDetectorParams(const DetectorParams& p) {
  checkRanges(p);
  const ColourOnlyParams& c = p.colour_only;
  if (c.canny_high < c.canny_low)
    throw InputError(fmt::format("colour_only.canny_high ({}) must be at least colour_only.canny_low ({})", c.canny_high,
                                 c.canny_low));
}

}  // namespace vkpose
