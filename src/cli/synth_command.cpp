// `vkpose synth --mesh MESH ... --poses DIR|random --images N --seed S --out DIR`: a synthetic
// multi-instance BOP dataset (include/vkpose/synth.hpp does the work).
#include <charconv>
#include <cmath>
#include <string>

#include <fmt/format.h>

#include "cli/commands.hpp"
#include "util/progress.hpp"
#include "vkpose/bank.hpp"
#include "vkpose/error.hpp"
#include "vkpose/synth.hpp"

namespace vkpose::cli {

using util::ProgressBar;

namespace {
struct SynthOptions {
  std::string units = "auto", layout = "table", instances = "1:3", camera, out, camera_distance, bin_size, sensor;
  bool force = false;
  SynthParams params;
};

int toInt(const std::string& text, const char* flag) {
  int v = 0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), v);
  if (text.empty() || ec != std::errc() || end != text.data() + text.size())
    throw InputError(fmt::format("{} '{}': expected a whole number", flag, text));
  return v;
}

/// "N" or "MIN:MAX".
std::pair<int, int> parseRange(const std::string& text) {
  const auto colon = text.find(':');
  if (colon == std::string::npos) {
    const int n = toInt(text, "--instances");
    return {n, n};
  }
  return {toInt(text.substr(0, colon), "--instances"), toInt(text.substr(colon + 1), "--instances")};
}

/// "A:B" or "A:B:C", metres; `what` names the flag.
std::vector<float> parseMetres(const std::string& text, const char* what, std::size_t min_count, std::size_t max_count) {
  std::vector<float> out;
  std::size_t start = 0;
  while (true) {
    const std::size_t colon = text.find(':', start);
    const std::string part = text.substr(start, colon == std::string::npos ? std::string::npos : colon - start);
    float v = 0.f;
    const auto [end, ec] = std::from_chars(part.data(), part.data() + part.size(), v);
    if (part.empty() || ec != std::errc() || end != part.data() + part.size() || !std::isfinite(v))
      throw InputError(fmt::format("{} '{}': expected numbers in metres separated by ':'", what, text));
    out.push_back(v);
    if (colon == std::string::npos) break;
    start = colon + 1;
  }
  if (out.size() < min_count || out.size() > max_count)
    throw InputError(fmt::format("{} '{}': expected {} numbers", what, text,
                                 min_count == max_count ? std::to_string(min_count)
                                                        : fmt::format("{} or {}", min_count, max_count)));
  return out;
}

const char* unitName(MeshUnits u) { return u == MeshUnits::Millimetres ? "mm" : "m"; }
}  // namespace

Runner addSynthCommand(CLI::App& app, const GlobalOptions& global) {
  auto opt = std::make_shared<SynthOptions>();
  auto& p = opt->params;
  auto* sub = app.add_subcommand("synth", "Render a synthetic multi-instance RGB-D dataset in BOP format");
  sub->add_option("--mesh", p.meshes, "Object mesh (STL, PLY, OBJ); repeat for several objects, obj_id 1, 2, ...")
      ->required();
  sub->add_option("--units", opt->units, "Mesh units: mm, m, or auto (from the object's size)")->capture_default_str();
  sub->add_option("--poses", p.poses,
                  "'random' (physically plausible placements), or Tejani et al. pose files: a folder of posesN.txt "
                  "(one mesh), or a folder with a subfolder per mesh named like its file (case, '_' and '-' "
                  "ignored: juicecarton.stl takes juice_carton/). Image i shows mesh i mod M at the poses of its "
                  "(i div M)-th file in the order of N, verbatim, on a table fitted under them")
      ->required();
  sub->add_option("--images", p.images, "Number of images to render (1 or more)")->required();
  sub->add_option("--seed", p.seed, "Random seed: the same arguments and seed give the same files")
      ->capture_default_str();
  sub->add_option("--out", opt->out, "Output folder (BOP layout); must be empty or new unless --force")->required();
  sub->add_option("--camera", opt->camera,
                  "BOP camera.json for the intrinsics and image size (default: Tejani et al.'s PrimeSense, "
                  "fx 571.97 fy 571.01 cx 319.5 cy 239.5, 640x480)");
  sub->add_option("--layout", opt->layout, "random: objects on a 'table' or piled in a 'bin'")
      ->check(CLI::IsMember({"table", "bin"}))
      ->capture_default_str();
  sub->add_option("--instances", opt->instances, "random: instances of each mesh per image, N or MIN:MAX")
      ->capture_default_str();
  sub->add_option("--clutter", p.clutter, "Boxes and cylinders per image that are not in the ground truth")
      ->capture_default_str();
  sub->add_option("--camera-distance", opt->camera_distance,
                  "random: the camera's distance to the point it looks at, FROM:TO metres (e.g. 0.3:0.45 for small "
                  "parts), tilted up to 35 degrees; default: on a table, its height above it, 0.6 to 1.2 m, tilted "
                  "up to 35 degrees; over a bin, a bin-picking cell's camera 0.8 to 1.0 m from the bin's floor, "
                  "tilted up to 15 degrees, within the distances train's default --radii covers");
  sub->add_option("--bin-size", opt->bin_size,
                  "bin layout: inside X:Y (metres) and optionally the wall height X:Y:H; default: 0.40:0.30:0.15, "
                  "made smaller for small parts seen from close by");
  sub->add_option("--symmetric", p.symmetric,
                  "obj_id of a mesh with a continuous symmetry about its z axis (models_info.json's "
                  "symmetries_continuous, so ADI scores it); repeat for several");
  addSensorOption(sub, opt->sensor,
                  "the depth noise and step the images are rendered with; close-range also renders a stereo "
                  "camera's 9-pixel matching window (rounded edges, thin parts lost) and holes on metal");
  sub->add_flag("--metal", p.metal_parts,
                "The parts are bare metal: grey, with highlights from the light and from a lamp beside the lens, and "
                "with --sensor close-range, holes in their depth where they face the camera");
  sub->add_option("--scaled-copies", p.scaled_copies,
                  "random: per image, copies of the parts scaled by 0.8-0.9 or 1.1-1.2 placed among them, not in "
                  "the ground truth (test/000001/scaled/IMAGE.json): look-alikes vkpose eval counts when reported "
                  "as the part")
      ->capture_default_str();
  sub->add_flag("--grey", p.greyscale, "A monochrome camera: the colour image's three channels are the same grey");
  sub->add_flag("--force", opt->force,
                "Write into a non-empty --out: removes its models/, test/000001/ and camera.json first");
  return [opt, &global]() {
    SynthParams params = opt->params;
    params.units = parseMeshUnits(opt->units);
    params.placement.layout = opt->layout == "bin" ? Layout::Bin : Layout::Table;
    std::tie(params.min_instances, params.max_instances) = parseRange(opt->instances);
    if (!opt->camera.empty()) params.camera = loadCamera(opt->camera);
    if (!opt->sensor.empty()) params.noise = synthNoise(opt->sensor);
    if (!opt->camera_distance.empty()) {
      const auto d = parseMetres(opt->camera_distance, "--camera-distance", 2, 2);
      params.camera_range = cameraAtDistances(d[0], d[1]);
    }
    if (!opt->bin_size.empty()) {
      const auto b = parseMetres(opt->bin_size, "--bin-size", 2, 3);
      params.placement.bin_inner_m = {b[0], b[1]};
      if (b.size() == 3) params.placement.bin_wall_height_m = b[2];
      params.fit_bin_to_parts = false;
    }
    validateSynthParams(params);  // bad input is exit 1 even on a machine without a device
    GpuContext ctx(global.gpu());
    ProgressBar bar("rendering", global.quiet);
    const SynthSummary s = generateSyntheticDataset(ctx, params, opt->out, opt->force,
                                                    [&](int done, int total) {
                                                      bar.update(static_cast<std::size_t>(done),
                                                                 static_cast<std::size_t>(total));
                                                    });
    bar.finish();
    if (!global.quiet)
      for (std::size_t i = 0; i < s.mesh_reports.size(); ++i)
        if (s.mesh_reports[i].inferred)
          fmt::print("{}: units {} (inferred: the file's diameter is {:.4g} units; pass --units to override)\n",
                     params.meshes[i], unitName(s.mesh_reports[i].units), s.mesh_reports[i].file_diameter);
    fmt::print("wrote {} image{} with {} instances of {} object{} to {} ({:.0f} ms per image on {})\n", s.images,
               s.images == 1 ? "" : "s", s.instances, params.meshes.size(), params.meshes.size() == 1 ? "" : "s",
               opt->out, s.ms_per_image, ctx.device().name);
    const auto [near_m, far_m] = coveredDistances(ViewSamplingParams{}.radii);
    if (s.instances > 0)
      fmt::print("the instances lie {:.2f}-{:.2f} m from the camera{}\n", s.nearest_m, s.farthest_m,
                 s.nearest_m < near_m || s.farthest_m > far_m
                     ? fmt::format(": a bank trained at train's default --radii finds them at {:.2f}-{:.2f} m; train "
                                   "with --radii covering these distances{}",
                                   near_m, far_m, opt->camera_distance.empty() ? ", or set --camera-distance" : "")
                     : std::string());
    if (s.left_out > 0)
      fmt::print("{} random instance{} found no free place and {} left out\n", s.left_out,
                 s.left_out == 1 ? "" : "s", s.left_out == 1 ? "was" : "were");
    return kOk;
  };
}

}  // namespace vkpose::cli
