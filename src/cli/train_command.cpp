// `vkpose train MESH --out BANK`: render the mesh from every training view and store the
// LINEMOD templates in a bank file.
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <optional>
#include <vector>

#include <fmt/core.h>

#include "bench/bench_support.hpp"
#include "cli/commands.hpp"
#include "util/progress.hpp"
#include "vkpose/bank.hpp"
#include "vkpose/error.hpp"

namespace vkpose::cli {

using util::ProgressBar;

namespace {
struct TrainOptions {
  std::string mesh, out, units = "auto", radii = "0.6:1.0:0.1", inplane = "-60:60:10", hemisphere = "upper", camera,
      up = "auto", resting = "auto", full_turn_within = "auto";
  int views = 216, features = 63;
  float max_view_angle = 180.f, near_symmetry_tolerance = TrainingParams{}.near_symmetry_tolerance;
  bool symmetric = false, force = false, allow_small = false;
};

const char* unitName(MeshUnits u) { return u == MeshUnits::Millimetres ? "millimetres" : "metres"; }

TrainingParams trainingParamsFrom(const TrainOptions& o) {
  TrainingParams p;
  p.views.viewpoints = o.views;
  p.views.radii = parseSteppedRange(o.radii, "--radii");
  p.views.inplane_deg = parseSteppedRange(o.inplane, "--inplane");
  p.views.full_sphere = o.hemisphere == "full";
  p.features_per_modality = o.features;
  p.symmetric = o.symmetric;
  p.near_symmetry_tolerance = o.near_symmetry_tolerance;
  if (!o.camera.empty()) p.camera = loadCamera(o.camera);
  if (o.up != "auto") p.views.up = parseUpAxis(o.up);
  validateTrainingParams(p);
  return p;
}
/// What training chose: the up axis (and, with -v, why) and the other resting poses.
void printPlan(const TrainingPlan& plan, const TrainingParams& params, const Mesh& mesh, const TrainOptions& opt,
               bool verbose) {
  if (opt.up == "auto") {
    fmt::print("up axis: {} (auto: {})\n", upAxisName(params.views.up), plan.found.reason);
    if (verbose)
      for (const RestingCandidate& c : plan.found.candidates)
        fmt::print("  {} up: base {:.0f}% of the footprint, {:.0f} degrees off the axis, centre of mass {:.1f} mm "
                   "inside it{}\n",
                   upAxisName(c.up), 100.f * c.support, c.tilt_deg, 1e3f * c.margin_m, c.stands() ? ", stands" : "");
  } else {
    fmt::print("up axis: {} (--up)\n", upAxisName(params.views.up));
  }
  if (!params.views.full_sphere) {
    const bool trained = !params.views.other_ups.empty();
    fmt::print("other resting poses: {} ({})\n", restingUpsText(plan.other_ups),
               plan.other_ups.empty() ? "it stands on no other side, or near-symmetries cover them"
               : trained && opt.resting == "auto"
                   ? fmt::format("a hemisphere of views about each as well: {} lies any way up in a bin; --resting "
                                 "up trains it standing only",
                                 isSmallPart(mesh.diameter)
                                     ? fmt::format("a part {:.0f} mm across", 1e3f * mesh.diameter)
                                     : fmt::format("a part seen from {:.2f} m (nearer than {:.1f} m: bin picking)",
                                                   params.views.radii.low(),
                                                   kPileDistanceM))
               : trained ? "a hemisphere of views about each as well"
                     : "not trained: pass --resting all to find it lying down too");
  }
  if (params.views.full_turn_within_deg > 0.f)
    fmt::print("in-plane: {}:{}:{} deg, the whole turn within {:.0f} deg of {} ({})\n", params.views.inplane_deg.from,
               params.views.inplane_deg.to, params.views.inplane_deg.step, params.views.full_turn_within_deg,
               params.views.other_ups.empty() ? "the top" : "each up axis",
               opt.full_turn_within == "auto" ? "auto: seen from above, a part in a bin lies at any turn; "
                                                "--full-turn-within 0 keeps the range everywhere"
                                              : "--full-turn-within");
}

/// --full-turn-within: "auto" (planTraining decides) or degrees.
std::optional<float> fullTurnWithin(const std::string& text) {
  if (text == "auto") return std::nullopt;
  float deg = 0.f;
  char tail = 0;
  if (std::sscanf(text.c_str(), "%f%c", &deg, &tail) != 1 || !(deg >= 0.f && deg <= 90.f))
    throw InputError(fmt::format("--full-turn-within '{}': auto, or degrees from 0 to 90", text));
  return deg;
}

/// Templates without a depth feature although the bank was trained with depth.
std::size_t colourOnlyTemplates(const TemplateBank& bank) {
  if (!bank.params.features.use_depth) return 0;
  return static_cast<std::size_t>(std::count_if(bank.templates.begin(), bank.templates.end(), [](const BankTemplate& t) {
    for (const auto& level : t.linemod.levels)
      for (const auto& f : level.features)
        if (f.modality == Modality::DepthNormal) return false;
    return true;
  }));
}

/// `vkpose train`.
ExitCode runTrain(const TrainOptions& opt, const GlobalOptions& global) {
  TrainingParams params = trainingParamsFrom(opt);
  const std::optional<float> full_turn_within = fullTurnWithin(opt.full_turn_within);
  if (std::filesystem::exists(opt.out) && !opt.force)
    throw InputError(fmt::format("{} exists: pass --force to overwrite it", opt.out));
  MeshLoadReport report;
  const Mesh mesh = loadMesh(opt.mesh, parseMeshUnits(opt.units), &report);
  if (!global.quiet) {
    fmt::print("mesh: {} ({} triangles, {} vertices{}{})\n", mesh.name, mesh.faces.size(), mesh.vertices.size(),
               mesh.colours.empty() ? "" : ", vertex colours", mesh.normals.empty() ? "" : ", normals");
    if (report.inferred)
      fmt::print("units: {} (inferred: the file's diameter is {:.4g} units; pass --units to override)\n",
                 unitName(report.units), report.file_diameter);
    fmt::print("diameter: {:.4f} m\n", mesh.diameter);
  }
  const PartSizeEvidence size = partSizeEvidence(mesh, params);
  if (size.too_small() && !opt.allow_small) throw InputError(size.refusal());
  if (!global.quiet) fmt::print("size: {}\n", size.summary());
  for (const std::string& w : trainingWarnings(mesh, params)) fmt::print(stderr, "vkpose: warning: {}\n", w);
  const TrainingPlan plan =
      planTraining(mesh, params, opt.up == "auto", opt.resting, opt.max_view_angle, full_turn_within);
  printPlan(plan, params, mesh, opt, global.verbose);
  GpuContext ctx(global.gpu());
  ProgressBar bar("training", global.quiet);
  TrainingTimings timings;
  const TemplateBank bank = trainTemplatesFromViews(
      ctx, mesh, params, plan.views, [&](std::size_t done, std::size_t total) { bar.update(done, total); }, &timings);
  bar.finish();
  saveBank(bank, opt.out);
  const auto bytes = std::filesystem::file_size(opt.out);
  fmt::print("templates: {}\n", bank.templates.size());
  printNearSymmetries(bank);
  if (!global.quiet) {
    if (timings.dropped) fmt::print("dropped: {} views with too few features\n", timings.dropped);
    if (const std::size_t colour_only = colourOnlyTemplates(bank))
      fmt::print("colour only: {} templates whose views' depth shows too little of the part (thin, seen edge on)\n",
                 colour_only);
    fmt::print("time: {:.1f} s (render {:.1f} s, features {:.1f} s) on {}, {:.0f} templates/s\n",
               timings.total_ms / 1e3, timings.render_ms / 1e3, timings.features_ms / 1e3, ctx.device().name,
               1e3 * static_cast<double>(bank.templates.size()) / timings.total_ms);
    fmt::print("bank: {} ({:.1f} MiB)\n", opt.out, static_cast<double>(bytes) / (1 << 20));
  }
  bench::printKernelProfile();
  return kOk;
}
}  // namespace

Runner addTrainCommand(CLI::App& app, const GlobalOptions& global) {
  auto opt = std::make_shared<TrainOptions>();
  auto* sub = app.add_subcommand("train", "Render a mesh from many views and write its LINEMOD template bank");
  sub->add_option("mesh", opt->mesh, "Mesh file: STL (binary or ASCII), PLY (colours kept) or OBJ")->required();
  sub->add_option("-o,--out", opt->out, "Template bank to write (.vkpb); never overwritten without --force")->required();
  sub->add_option("--units", opt->units, "Mesh units: mm, m, or auto (from the object's size)")
      ->check(CLI::IsMember({"mm", "m", "auto"}))
      ->capture_default_str();
  sub->add_option("--views", opt->views, "Viewpoints on the (hemi)sphere (Fibonacci lattice)")
      ->check(CLI::Range(1, 100000))
      ->capture_default_str();
  sub->add_option("--radii", opt->radii, "Camera distances FROM:TO:STEP, metres")->capture_default_str();
  sub->add_option("--inplane", opt->inplane, "In-plane rotations FROM:TO:STEP, degrees")->capture_default_str();
  sub->add_option("--full-turn-within", opt->full_turn_within,
                  "Viewpoints within this angle of an up axis (degrees, 0 to 90) take in-plane rotations over the "
                  "whole turn at --inplane's step: seen from near its top, a part's turn in the image is chance, not "
                  "the camera's roll; auto: 40 where the lying poses are trained (--resting), else 0")
      ->capture_default_str();
  sub->add_option("--hemisphere", opt->hemisphere, "Viewpoints on the upper hemisphere or the full sphere")
      ->check(CLI::IsMember({"upper", "full"}))
      ->capture_default_str();
  sub->add_option("--up", opt->up,
                  "The object's up axis in the mesh's frame: auto (the end it stands on, +z first), or +x, -x, +y, "
                  "-y, +z, -z. Views are sampled above it and image up follows it")
      ->check(CLI::IsMember({"auto", "+x", "-x", "+y", "-y", "+z", "-z"}))
      ->capture_default_str();
  sub->add_option("--resting", opt->resting,
                  "up: views about the up axis only (objects standing upright); all: also a hemisphere about each "
                  "other pose the object rests in (lying on a side, upside down) that no near-symmetry covers, for "
                  "objects tipped over or in bins: up to 6x the templates and the matching time; auto: all for a "
                  "part smaller than 10 cm across or trained nearer than 0.5 m (parts in bins lie any way up), up "
                  "otherwise")
      ->check(CLI::IsMember({"auto", "all", "up"}))
      ->capture_default_str();
  sub->add_flag("--allow-small", opt->allow_small,
               "Train a part too small to tell from its neighbourhood where it is trained (under 2 cells of "
               "LINEMOD's coarsest level across, or under 1 wide, at the nearest --radii), which train refuses otherwise");
  sub->add_option("--max-view-angle", opt->max_view_angle,
                  "Keep only viewpoints within this angle of the object's up axis, degrees (e.g. 40 for parts that stand "
                  "upright under a camera looking down)")
      ->check(CLI::Range(1.0, 180.0))
      ->capture_default_str();
  sub->add_option("--features", opt->features, "Features per modality and pyramid level (LINEMOD: 63)")
      ->check(CLI::Range(4, 4096))
      ->capture_default_str();
  sub->add_option("--camera", opt->camera, "BOP camera.json of the sensor (focal lengths); default: LINEMOD's Kinect");
  sub->add_flag("--symmetric", opt->symmetric, "The object is symmetric (evaluation scores it with ADI)");
  sub->add_option("--near-symmetry-tolerance", opt->near_symmetry_tolerance,
                  "Turns that map the surface onto itself within this share of the diameter are near-symmetries: "
                  "detection lets the mesh's colours choose among them (0: none)")
      ->check(CLI::Range(0.0, 0.2))
      ->capture_default_str();
  sub->add_flag("--force", opt->force, "Overwrite --out if it exists");
  return [opt, &global]() { return runTrain(*opt, global); };
}

}  // namespace vkpose::cli
