// `vkpose info`: the Vulkan devices, the one vkpose would choose, and the limits that matter.
#include <fmt/core.h>

#include "cli/commands.hpp"
#include "vkpose/error.hpp"

namespace vkpose::cli {

Runner addInfoCommand(CLI::App& app, const GlobalOptions& global) {
  auto* sub = app.add_subcommand("info", "List Vulkan devices, the chosen one and its limits");
  (void)sub;
  return [&global]() {
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
