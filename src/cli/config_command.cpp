// `vkpose config --print-defaults | --explain`, and the `--config FILE` option of the commands
// that detect (detect, eval, demo, bench).
#include <fmt/core.h>

#include "cli/commands.hpp"
#include "vkpose/config.hpp"

namespace vkpose::cli {

void addConfigOption(CLI::App* sub, std::string& path) {
  sub->add_option("--config", path,
                  "JSON file of stage parameters (start from 'vkpose config --print-defaults'); flags given on the "
                  "command line win");
}

void addSensorOption(CLI::App* sub, std::string& sensor, const std::string& what) {
  std::string names;
  for (const auto& n : sensorProfileNames()) names += (names.empty() ? "" : "|") + n;
  sub->add_option("--sensor", sensor,
                  fmt::format("Depth sensor: {} (default {}), or a JSON file {{\"axial_sigma_at_1m\": m, "
                              "\"quantization_m\": m}}; {}",
                              names, sensorProfileNames().front(), what));
}

DetectorParams withConfig(const std::string& path, const DetectorParams& from_flags) {
  if (path.empty()) return from_flags;
  return mergeConfig(DetectorParams{}, loadConfig(path), from_flags);
}

Runner addConfigCommand(CLI::App& app, const GlobalOptions&) {
  auto* sub = app.add_subcommand("config", "Print the stage parameters a --config file can set");
  auto print = std::make_shared<bool>(false), explain = std::make_shared<bool>(false);
  auto check = std::make_shared<std::string>();
  auto* group = sub->add_option_group("what", "What to print");
  group->add_flag("--print-defaults", *print, "Print every stage parameter's default as a config file (JSON)");
  group->add_flag("--explain", *explain, "Print every stage parameter with its default, meaning and unit");
  group->add_option("--check", *check, "Read a config file and print the parameters it gives (all of them)");
  group->require_option(1);
  return [print, explain, check]() {
    if (*print) fmt::print("{}", configJson(DetectorParams{}));
    if (*explain) fmt::print("{}", configTable());
    if (!check->empty()) fmt::print("{}", configJson(loadConfig(*check)));
    return 0;
  };
}

}  // namespace vkpose::cli
