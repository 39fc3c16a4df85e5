// `vkpose config --print-defaults | --explain`, and the `--config FILE` option of the commands
// that detect (detect, eval, demo, bench).
#include <algorithm>
#include <cctype>
#include <stdexcept>
#include <type_traits>
#include <variant>

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
                              "\"quantization_m\": m, \"small_parts_unreliable\": bool}}; {}",
                              names, sensorProfileNames().front(), what));
}

namespace {
/// The flag of one table entry, bound to the field its pointer names.
CLI::Option* addFieldFlag(CLI::App* sub, const ConfigField* f, const std::string& note) {
  std::string help = f->doc + note + fmt::format(" ({}.{})", f->section, f->key);
  help[0] = static_cast<char>(std::toupper(static_cast<unsigned char>(help[0])));
  return std::visit(
      [&](auto* field) -> CLI::Option* {
        if constexpr (std::is_same_v<std::remove_pointer_t<decltype(field)>, bool>) {
          if (f->flag[0] != '!') return sub->add_flag(f->flag, *field, help);
          return sub->add_flag(f->flag, *field,
                               fmt::format("Sets {}.{} false; it means: {}{}", f->section, f->key, f->doc, note));
        } else {
          const ValueRange range = f->range;
          const CLI::Validator in_range(
              [range](std::string& text) -> std::string {
                double v = 0.0;
                try {
                  v = std::stod(text);
                } catch (const std::exception&) {
                  return "not a number: " + text;
                }
                return range.contains(v) ? std::string() : fmt::format("{} is not {}", text, range.text());
              },
              range.text());
          return sub->add_option(f->flag, *field, help)->check(in_range)->capture_default_str();
        }
      },
      f->value);
}
}  // namespace

CLI::Option* addParamFlag(CLI::App* sub, DetectorParams& params, const std::string& flag, const std::string& note) {
  const std::vector<ConfigField> fields = configFields(params);
  const auto f = std::find_if(fields.begin(), fields.end(),
                              [&](const ConfigField& c) { return c.flag == flag || c.flag == "!" + flag; });
  if (f == fields.end()) throw std::logic_error("no stage parameter has the flag " + flag);
  return addFieldFlag(sub, &*f, note);
}

void addStageFlags(CLI::App* sub, DetectorParams& params, const std::string& group) {
  for (const ConfigField& f : configFields(params))
    if (!f.flag.empty()) addFieldFlag(sub, &f, {})->group(group);
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
