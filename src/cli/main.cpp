// vkpose command line: one subcommand per job; errors become one clear line and an exit code.
#include <iostream>
#include <map>

#include <opencv2/core/utility.hpp>

#include "cli/commands.hpp"
#include "vkpose/error.hpp"

int main(int argc, char** argv) {
  using namespace vkpose::cli;
  CLI::App app{"vkpose: detection and 6-DoF pose of texture-poor objects in RGB-D images, on Vulkan", "vkpose"};
  app.set_version_flag("--version", std::string("vkpose ") + VKPOSE_VERSION);
  app.require_subcommand(1);
  GlobalOptions global;
  app.add_option("--device", global.device, "Vulkan device index (see 'vkpose info'); also VKPOSE_DEVICE")
      ->check(CLI::NonNegativeNumber);
  app.add_flag("-q,--quiet", global.quiet, "Print only results and errors");
  app.add_flag("-v,--verbose", global.verbose, "Print more detail (e.g. why each rejected hypothesis was rejected)");
  // The global flags work after the subcommand too (`vkpose detect ... -v`): what a
  // subcommand does not know goes up to its parent.
  app.fallthrough();
  app.footer(
      "Exit codes: 0 ok, 1 bad input (missing or corrupt file, bad value), 2 usage error, 3 no usable Vulkan "
      "device.");

  std::map<CLI::App*, Runner> runners;
  auto add = [&](Runner (*adder)(CLI::App&, const GlobalOptions&)) {
    const auto before = app.get_subcommands({});
    Runner r = adder(app, global);
    for (auto* sub : app.get_subcommands({}))
      if (std::find(before.begin(), before.end(), sub) == before.end()) runners[sub] = r;
  };
  add(addInfoCommand);
  add(addTrainCommand);
  add(addDetectCommand);
  add(addSynthCommand);
  add(addEvalCommand);
  add(addBenchCommand);
  add(addDemoCommand);
  add(addConfigCommand);

  // Subcommands registered with a callback (bench train, bench soak) run inside parse(), so
  // their errors must be caught around it too.
  try {
    try {
      app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
      const int code = app.exit(e);
      return code == 0 ? kOk : kUsage;
    }
    for (auto* sub : app.get_subcommands())
      if (auto it = runners.find(sub); it != runners.end()) return it->second();
    return kUsage;
  } catch (const vkpose::InputError& e) {
    std::cerr << "vkpose: error: " << e.what() << "\n";
    return kBadInput;
  } catch (const vkpose::DeviceError& e) {
    std::cerr << "vkpose: device error: " << e.what() << "\n";
    return kNoDevice;
  } catch (const std::exception& e) {
    std::cerr << "vkpose: error: " << e.what() << "\n";
    return kBadInput;
  }
}
