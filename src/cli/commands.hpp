#pragma once
// The vkpose commands. Each registers its subcommand and flags on the CLI11 app and returns
// the function that runs it.
#include <functional>

#include <CLI/CLI.hpp>

#include "vkpose/detector.hpp"
#include "vkpose/device.hpp"

namespace vkpose {
struct PickParams;
}

namespace vkpose::cli {

/// Exit codes, documented in README.md and docs/reliability.md.
enum ExitCode { kOk = 0, kBadInput = 1, kUsage = 2, kNoDevice = 3 };

struct GlobalOptions {
  int device = -1;  ///< -1: automatic
  bool quiet = false;
  bool verbose = false;  ///< print more detail (e.g. every rejected hypothesis and why)
  GpuOptions gpu() const {
    GpuOptions o;
    if (device >= 0) o.device_index = device;
    return o;
  }
};

using Runner = std::function<int()>;

Runner addInfoCommand(CLI::App& app, const GlobalOptions& global);
Runner addBenchCommand(CLI::App& app, const GlobalOptions& global);
Runner addDemoCommand(CLI::App& app, const GlobalOptions& global);
Runner addTrainCommand(CLI::App& app, const GlobalOptions& global);
Runner addDetectCommand(CLI::App& app, const GlobalOptions& global);
Runner addSynthCommand(CLI::App& app, const GlobalOptions& global);
Runner addEvalCommand(CLI::App& app, const GlobalOptions& global);
Runner addConfigCommand(CLI::App& app, const GlobalOptions& global);
/// Adds `--config FILE` (stage parameters, config.hpp) to a command.
void addConfigOption(CLI::App* sub, std::string& path);
/// `--pick-order`, `--max-tilt` and `--min-outline-fit`: how picks are planned and ordered
/// (detect and eval alike), each a usage error without `grasps` (`--grasps`), where it would do
/// nothing; the order is parsed by parsePickOrder when the command runs.
void addPickFlags(CLI::App* sub, CLI::Option* grasps, std::string& pick_order, PickParams& pick,
                  const std::string& group);
/// `--sensor NAME|FILE` (config.hpp's sensorProfile()); `what` says what the sensor sets.
void addSensorOption(CLI::App* sub, std::string& sensor, const std::string& what);
/// The command-line flag of a stage parameter (`flag` as the parameter table in config_io.cpp
/// names it, "--no-pose" for "!--no-pose"): its meaning (and `note`), range and default from
/// the table, bound to the field of `params`.
CLI::Option* addParamFlag(CLI::App* sub, DetectorParams& params, const std::string& flag, const std::string& note = {});
/// Every stage parameter with a flag in the table, in pipeline order, in `group` of the help.
void addStageFlags(CLI::App* sub, DetectorParams& params, const std::string& group);
/// The stage parameters of a command: the config file's (when `path` is not empty), overridden
/// by the flags that differ from the defaults.
DetectorParams withConfig(const std::string& path, const DetectorParams& from_flags);
/// The bank's near-symmetries, one line each (train and info --bank).
void printNearSymmetries(const TemplateBank& bank);
/// "+x up, -x up" (or "none") for the other resting poses' up axes.
std::string restingUpsText(const std::vector<Eigen::Vector3f>& ups);
/// `vkpose bench train`, registered under the `bench` subcommand; the runner runs it.
Runner addBenchTrainCommand(CLI::App& bench, const GlobalOptions& global);
/// `vkpose bench detect`, registered under the `bench` subcommand; the runner runs it.
Runner addBenchDetectCommand(CLI::App& bench, const GlobalOptions& global);
void addBenchSoakCommand(CLI::App& bench, const GlobalOptions& global);  ///< `vkpose bench soak`

}  // namespace vkpose::cli
