// `vkpose info`: the Vulkan devices, the one vkpose would choose, and the limits that matter.
#include <fmt/core.h>
#include <fmt/ranges.h>

#include "cli/commands.hpp"
#include "vkpose/bank.hpp"
#include "vkpose/error.hpp"

namespace vkpose::cli {

std::string restingUpsText(const std::vector<Eigen::Vector3f>& ups) {
  if (ups.empty()) return "none";
  std::vector<std::string> names;
  for (const Eigen::Vector3f& up : ups) names.push_back(upAxisName(up) + " up");
  return fmt::format("{}", fmt::join(names, ", "));
}

void printNearSymmetries(const TemplateBank& bank) {
  if (bank.near_symmetries.empty()) {
    fmt::print("near-symmetries: none within {:.1f}% of the diameter\n", 100.f * bank.params.near_symmetry_tolerance);
    return;
  }
  fmt::print("near-symmetries: {} within {:.1f}% of the diameter ({})\n", bank.near_symmetries.size(),
             100.f * bank.params.near_symmetry_tolerance,
             bank.mesh.colours.empty()
                 ? "the mesh has no colours: detection reports such poses ambiguous unless depth tells them apart"
                 : "detection lets the mesh's colours choose among them");
  for (const auto& s : bank.near_symmetries) fmt::print("  {}\n", describe(s));
}

namespace {
void printBankSummary(const TemplateBank& bank, const std::string& path) {
  const auto& p = bank.params;
  std::size_t features = 0;
  for (const auto& t : bank.templates)
    for (const auto& l : t.linemod.levels) features += l.features.size();
  fmt::print("bank: {}\n", path);
  fmt::print("object: {}\n", bank.object);
  fmt::print("mesh hash: {:016x}\n", bank.mesh_hash);
  fmt::print("diameter: {:.4f} m\n", bank.diameter);
  fmt::print("symmetric: {}\n", bank.symmetric ? "yes" : "no");
  fmt::print("templates: {}\n", bank.templates.size());
  fmt::print("up axis: {}\n", upAxisName(p.views.up));
  fmt::print("other resting poses: {}\n", restingUpsText(p.views.other_ups));
  fmt::print("views: {} viewpoints ({}), radii {}:{}:{} m, in-plane {}:{}:{} deg\n", p.views.viewpoints,
             p.views.full_sphere            ? "full sphere"
             : p.views.other_ups.empty() ? "hemisphere above the up axis"
                                         : "a hemisphere above the up axis and one above each other resting pose's", p.views.radii.from, p.views.radii.to,
             p.views.radii.step, p.views.inplane_deg.from, p.views.inplane_deg.to, p.views.inplane_deg.step);
  if (p.views.full_turn_within_deg > 0.f)
    fmt::print("  the whole turn in-plane within {:.0f} deg of {}\n", p.views.full_turn_within_deg,
               p.views.other_ups.empty() ? "the top" : "each up axis");
  fmt::print("features: {} per modality and level, T = {}, modalities {}{}, {:.1f} per template\n",
             p.features_per_modality, fmt::join(p.features.T, ","), p.features.use_colour ? "colour " : "",
             p.features.use_depth ? "depth" : "",
             bank.templates.empty() ? 0.0 : static_cast<double>(features) / static_cast<double>(bank.templates.size()));
  fmt::print("camera: fx {:.2f} fy {:.2f}\n", p.camera.fx, p.camera.fy);
  // Which frames it serves: RGB-D needs the modalities it was trained with; colour only
  // needs colour templates (docs/colour_only.md).
  fmt::print("detects in: {}\n", p.features.use_colour && p.features.use_depth
                                      ? "RGB-D frames and colour-only frames (without depth: colour templates alone)"
                                  : p.features.use_colour ? "RGB-D and colour-only frames (colour templates)"
                                                          : "RGB-D frames only (no colour modality: not colour-only frames)");
  printNearSymmetries(bank);
}
}  // namespace

Runner addInfoCommand(CLI::App& app, const GlobalOptions& global) {
  auto* sub = app.add_subcommand("info", "List Vulkan devices, the chosen one and its limits; or describe a bank");
  auto bank_path = std::make_shared<std::string>();
  sub->add_option("--bank", *bank_path, "Describe this template bank instead (no device needed)");
  return [&global, bank_path]() {
    if (!bank_path->empty()) {
      printBankSummary(loadBank(*bank_path), *bank_path);
      return 0;
    }
    const auto devices = listGpuDevices();
    if (devices.empty()) throw DeviceError("no Vulkan device found: apt-get install mesa-vulkan-drivers (lavapipe)");
    const std::size_t chosen = chooseGpuDevice(devices, global.gpu());
    fmt::print("vkpose {}\n", VKPOSE_VERSION);
    fmt::print("Vulkan devices:\n");
    for (const auto& d : devices) {
      fmt::print("  [{}] {}{} ({}, Vulkan {}, {})\n", d.index, d.name, d.index == chosen ? "   <- chosen" : "", d.type,
                 d.api_version, d.driver);
      fmt::print("      max storage buffer range  {} MiB\n", d.max_storage_buffer_range >> 20);
      fmt::print("      shared memory / workgroup {} KiB\n", d.max_shared_memory >> 10);
      fmt::print("      subgroup size             {}\n", d.subgroup_size);
      fmt::print("      max workgroup invocations {}\n", d.max_workgroup_invocations);
      fmt::print("      max workgroups            {} x {} x {}\n", d.max_workgroup_count[0], d.max_workgroup_count[1],
                 d.max_workgroup_count[2]);
      fmt::print("      device-local memory       {} MiB\n", d.device_local_memory >> 20);
      if (!d.usable) fmt::print("      NOT USABLE: lacks {}\n", d.missing);
    }
    fmt::print("chosen: [{}] {}\n", devices[chosen].index, devices[chosen].name);
    return 0;
  };
}

}  // namespace vkpose::cli
