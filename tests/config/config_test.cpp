// The stage parameters (config.hpp, src/config/): the one parameter table and its ranges,
// the config file, the lengths that follow the object and the sensor, the sensor profiles.
#include <algorithm>
#include <filesystem>
#include <fstream>
#include <limits>
#include <set>
#include <string>
#include <variant>

#include <gtest/gtest.h>

#include "test_support.hpp"
#include "vkpose/config.hpp"
#include "vkpose/error.hpp"
#include "vkpose/synth.hpp"

using namespace vkpose;
namespace fs = std::filesystem;

namespace {
fs::path freshDir(const std::string& name) {
  const fs::path dir = test::scratchDir("vkpose_config_" + name + "_");
  fs::remove_all(dir);
  return dir;
}
}  // namespace

TEST(Config, DefaultsRoundTripAndValuesApply) {
  const DetectorParams defaults;
  const DetectorParams back = parseConfig(configJson(defaults), "defaults");
  EXPECT_EQ(configJson(back), configJson(defaults));
  const DetectorParams p =
      parseConfig(R"({"match": {"threshold": 85}, "verify": {"threshold": 0.5}, "refine": {"mls": false}})", "t");
  EXPECT_FLOAT_EQ(p.match.threshold, 85.f);
  EXPECT_FLOAT_EQ(p.verify.threshold, 0.5f);
  EXPECT_FALSE(p.refine.mls);
  EXPECT_EQ(p.cluster.min_templates, defaults.cluster.min_templates) << "what the file leaves out keeps its default";
  // Flags that differ from the defaults win over the file.
  DetectorParams flags;
  flags.cluster.min_templates = 7;
  const DetectorParams merged = mergeConfig(defaults, p, flags);
  EXPECT_EQ(merged.cluster.min_templates, 7);
  EXPECT_FLOAT_EQ(merged.match.threshold, 85.f);
}

TEST(ScaledLengths, ObjectsOfTenCentimetresAndMoreKeepTheDefaults) {
  const DetectorParams defaults;
  for (float diameter : {0.1f, 0.137f, 0.26f, 1.5f})
    for (float z : {0.3f, 0.8f, 1.2f})
      EXPECT_EQ(configJson(scaledForObject(defaults, diameter, z)), configJson(defaults)) << diameter << " m at " << z;
}

TEST(ScaledLengths, SmallPartsGetLengthsInProportionButNotBelowTheSensorNoise) {
  const DetectorParams defaults;
  // A 40 mm part at 0.36 m: the sensor's 1 mm depth step is its noise there.
  EXPECT_FLOAT_EQ(depthNoise(defaults.sensor, 0.36f), 0.001f);
  const DetectorParams p = scaledForObject(defaults, 0.04f, 0.36f);
  EXPECT_FLOAT_EQ(p.verify.resolution, 0.002f);              // 4 mm * 0.4 = 1.6 mm < 2 x noise
  EXPECT_FLOAT_EQ(p.refine.voxel_size, 0.002f);
  EXPECT_FLOAT_EQ(p.refine.mls_radius, 0.005f);              // 4 mm < 5 x noise
  EXPECT_FLOAT_EQ(p.verify.see_through_tolerance, 0.006f);   // 15 mm * 0.4
  EXPECT_FLOAT_EQ(p.verify.silhouette_jump, 0.004f);         // 10 mm * 0.4
  EXPECT_FLOAT_EQ(p.verify.crop_margin, 0.008f);
  // Fractions and everything else stay as they are.
  EXPECT_EQ(p.verify.threshold, defaults.verify.threshold);
  EXPECT_EQ(p.refine.fine_fraction, defaults.refine.fine_fraction);
  // The same part 2 m away: the noise (6 mm) sets the lengths, up to the defaults.
  const DetectorParams far = scaledForObject(defaults, 0.04f, 2.f);
  EXPECT_FLOAT_EQ(far.verify.resolution, defaults.verify.resolution);
  EXPECT_FLOAT_EQ(far.verify.silhouette_jump, defaults.verify.silhouette_jump);
  // A noiseless sensor: proportion alone.
  DetectorParams ideal;
  ideal.sensor = {0.f, 0.f};
  EXPECT_FLOAT_EQ(scaledForObject(ideal, 0.02f, 0.5f).verify.resolution, 0.0008f);
}

TEST(Config, ScaledLengthsAreTheirConfigFields) {
  // Each scaled length's accessor is the float field its section and key name in the file.
  DetectorParams p;
  const auto fields = configFields(p);
  for (const ScaledLength& s : scaledLengths()) {
    const auto f = std::find_if(fields.begin(), fields.end(),
                                [&](const ConfigField& c) { return c.section == s.section && c.key == s.key; });
    ASSERT_NE(f, fields.end()) << s.section << "." << s.key;
    ASSERT_TRUE(std::holds_alternative<float*>(f->value)) << s.section << "." << s.key;
    EXPECT_EQ(std::get<float*>(f->value), &s.field(p)) << s.section << "." << s.key;
  }
}

TEST(ScaledLengths, LengthsTheUserSetAreKept) {
  DetectorParams p = parseConfig(R"({"verify": {"resolution": 0.003}, "refine": {"voxel_size": 0}})", "t");
  const DetectorParams scaled = scaledForObject(p, 0.04f, 0.36f);
  EXPECT_FLOAT_EQ(scaled.verify.resolution, 0.003f);
  EXPECT_FLOAT_EQ(scaled.refine.voxel_size, 0.f) << "0 (no voxel filter) is the user's choice";
  EXPECT_FLOAT_EQ(scaled.verify.silhouette_jump, 0.004f) << "the others still follow the part";
  EXPECT_NE(scaledLengthsReport(p, 0.04f, 0.36f).find("verify.resolution 3.0 mm (set)"), std::string::npos);
  p.scale_lengths = false;
  EXPECT_FLOAT_EQ(scaledForObject(p, 0.04f, 0.36f).verify.silhouette_jump, DetectorParams{}.verify.silhouette_jump);
  // The switch and the sensor are config parameters, and --explain says which lengths follow.
  EXPECT_FALSE(parseConfig(R"({"detector": {"scale_lengths": false}})", "t").scale_lengths);
  EXPECT_FLOAT_EQ(parseConfig(R"({"sensor": {"quantization_m": 0.0005}})", "t").sensor.quantization_m, 0.0005f);
  EXPECT_THROW(parseConfig(R"({"sensor": {"axial_sigma_at_1m": -1}})", "t"), InputError);
  const std::string table = configTable();
  for (const ScaledLength& s : scaledLengths())
    EXPECT_NE(table.find(s.section + "." + s.key), std::string::npos);
  EXPECT_NE(table.find("[follows the object and the sensor]"), std::string::npos);
  EXPECT_NE(table.find("Parts smaller than 10 cm are also ranked and started differently"), std::string::npos);
}

TEST(SensorProfiles, NamesFilesAndWhatTheySet) {
  EXPECT_EQ(sensorProfileNames().front(), "kinect") << "the default first";
  const SensorParams kinect = sensorProfile("kinect"), d435 = sensorProfile("realsense-d435");
  EXPECT_EQ(kinect.axial_sigma_at_1m, DetectorParams{}.sensor.axial_sigma_at_1m) << "the default stays today's";
  EXPECT_EQ(kinect.quantization_m, DetectorParams{}.sensor.quantization_m);
  EXPECT_GT(d435.axial_sigma_at_1m, kinect.axial_sigma_at_1m);
  // synth renders what the detector assumes: the default profile is today's synth noise.
  const DepthNoiseParams today = synthNoise(), from_kinect = synthNoise(kinect), ideal = synthNoise(sensorProfile("ideal"));
  EXPECT_EQ(from_kinect.axial_sigma_at_1m, today.axial_sigma_at_1m);
  EXPECT_EQ(from_kinect.quantization_m, today.quantization_m);
  EXPECT_EQ(from_kinect.holes, today.holes);
  EXPECT_EQ(ideal.axial_sigma_at_1m, 0.f);
  EXPECT_EQ(ideal.holes, 0);
  EXPECT_EQ(ideal.edge_dropout, 0.f);
  // synth --sensor NAME: the profile's noise; close-range adds a stereo camera's window and metal's holes.
  const DepthNoiseParams close = synthNoise("close-range");
  EXPECT_EQ(close.axial_sigma_at_1m, sensorProfile("close-range").axial_sigma_at_1m);
  EXPECT_EQ(close.matching_window_px, 9);
  EXPECT_GT(close.specular_dropout, 0.f);
  EXPECT_EQ(synthNoise("kinect").matching_window_px, 0);
  EXPECT_EQ(synthNoise("kinect").specular_dropout, 0.f);
  // The close-range camera's depth of small parts is unreliable (the detector also matches
  // them on colour alone); the others' is not.
  EXPECT_TRUE(sensorProfile("close-range").small_parts_unreliable);
  for (const std::string name : {"kinect", "primesense", "realsense-d435", "ideal"})
    EXPECT_FALSE(sensorProfile(name).small_parts_unreliable) << name;
  // A noisier sensor makes a small part's lengths coarser at the same distance.
  DetectorParams p;
  p.sensor = d435;
  EXPECT_FLOAT_EQ(scaledForObject(p, 0.04f, 0.8f).verify.resolution, 2 * 0.0025f * 0.8f * 0.8f);
  EXPECT_FLOAT_EQ(scaledForObject(DetectorParams{}, 0.04f, 0.8f).verify.resolution, 0.002f);
  // A JSON file, and clear errors.
  const fs::path dir = freshDir("sensor");
  fs::create_directories(dir);
  const std::string file = (dir / "sensor.json").string(), bad = (dir / "bad.json").string();
  std::ofstream(file) << R"({"axial_sigma_at_1m": 0.002, "quantization_m": 0.0005})";
  std::ofstream(bad) << R"({"sigma": 0.002})";
  EXPECT_FLOAT_EQ(sensorProfile(file).axial_sigma_at_1m, 0.002f);
  EXPECT_FLOAT_EQ(sensorProfile(file).quantization_m, 0.0005f);
  EXPECT_FALSE(sensorProfile(file).small_parts_unreliable);
  const std::string stereo = (dir / "stereo.json").string(), not_bool = (dir / "not_bool.json").string();
  std::ofstream(stereo) << R"({"axial_sigma_at_1m": 0.002, "small_parts_unreliable": true})";
  std::ofstream(not_bool) << R"({"small_parts_unreliable": 1})";
  EXPECT_TRUE(sensorProfile(stereo).small_parts_unreliable);
  auto message = [](const std::string& what) {
    try {
      sensorProfile(what);
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(message("kinnect").find("kinect, primesense, realsense-d435, close-range, ideal"), std::string::npos);
  EXPECT_NE(message(bad).find("unknown key \"sigma\""), std::string::npos);
  EXPECT_NE(message(not_bool).find("small_parts_unreliable must be true or false"), std::string::npos);
}

// The one parameter table: each number has one range, its default lies in it, and a value
// just outside it is refused by the detector's checks with the parameter's name (the config
// file, the flags and Python all go through the same checks).
TEST(Config, EveryParameterHasOneRangeThatTheChecksUse) {
  DetectorParams defaults;
  std::set<std::string> flags;
  int refused = 0;
  for (const ConfigField& f : configFields(defaults)) {
    const std::string name = f.section + "." + f.key;
    if (!f.flag.empty()) {
      EXPECT_TRUE(flags.insert(f.flag).second) << "two parameters share the flag " << f.flag;
    }
    std::visit(
        [&](auto* field) {
          using T = std::remove_pointer_t<decltype(field)>;
          if constexpr (!std::is_same_v<T, bool>) {
            EXPECT_TRUE(f.range.contains(static_cast<double>(*field))) << name << " default outside " << f.range.text();
            std::vector<double> outside;
            if (f.range.min > -1e300) outside.push_back(f.range.min_open ? f.range.min : f.range.min - 1);
            if (f.range.max < 1e300) outside.push_back(f.range.max_open ? f.range.max : f.range.max + 1);
            for (const double v : outside) {
              if (v < static_cast<double>(std::numeric_limits<T>::lowest())) continue;  // unsigned below 0
              DetectorParams p;
              std::vector<ConfigField> fields = configFields(p);
              const auto it = std::find_if(fields.begin(), fields.end(), [&](const ConfigField& g) {
                return g.section == f.section && g.key == f.key;
              });
              *std::get<T*>(it->value) = static_cast<T>(v);
              try {
                validateDetectorParams(p);
                ADD_FAILURE() << name << " = " << v << " passed the checks; its range is " << f.range.text();
              } catch (const InputError& e) {
                EXPECT_NE(std::string(e.what()).find(name), std::string::npos) << e.what();
                ++refused;
              }
            }
          }
        },
        f.value);
  }
  EXPECT_GT(refused, 80) << "most parameters have a bound";
  EXPECT_TRUE(flags.count("--threshold") && flags.count("!--no-pose") && flags.count("--min-collision"));
  // The explanation shows the ranges.
  EXPECT_NE(configTable().find("(0, 100]"), std::string::npos);
}

TEST(Config, BadFilesAreClearErrors) {
  auto message = [](const std::string& text) {
    try {
      parseConfig(text, "my.json");
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(message("{ not json").find("my.json: not a JSON config file"), std::string::npos);
  EXPECT_NE(message(R"({"match": {"treshold": 85}})").find("unknown parameter match.treshold"), std::string::npos);
  EXPECT_NE(message(R"({"matching": {}})").find("unknown section \"matching\""), std::string::npos);
  EXPECT_NE(message(R"({"match": {"threshold": "high"}})").find("must be a number"), std::string::npos);
  EXPECT_NE(message(R"({"cluster": {"min_templates": 2.5}})").find("must be a whole number"), std::string::npos);
  EXPECT_NE(message(R"({"refine": {"mls": 1}})").find("must be true or false"), std::string::npos);
  EXPECT_NE(message(R"({"detector": {"threads": -1}})").find("out of range"), std::string::npos);
  EXPECT_NE(message(R"({"match": {"threshold": 150}})"), "no error") << "validated like the flags";
  EXPECT_NE(message("[1, 2]").find("a JSON object"), std::string::npos);
  EXPECT_THROW(loadConfig("/nonexistent/config.json"), InputError);
}
