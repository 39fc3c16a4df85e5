#pragma once
// Stage parameters in a file (`--config FILE`): every DetectorParams field, grouped by stage,
// as JSON. `vkpose config --print-defaults` writes the defaults to start from.
#include <cstddef>
#include <string>
#include <variant>
#include <vector>

#include "vkpose/detector.hpp"

namespace vkpose {

/// One parameter: where it lives in the file ("section": {"key": value}), what it means (with
/// its unit), and the field it sets.
struct ConfigField {
  std::string section, key, doc;
  std::variant<float*, double*, int*, unsigned*, std::size_t*, bool*> value;
};

/// Every stage parameter of `params`, in pipeline order; the pointers refer into `params`.
std::vector<ConfigField> configFields(DetectorParams& params);

/// The parameters as the config file holds them, pretty-printed JSON.
std::string configJson(const DetectorParams& params);

/// A table of every parameter: section.key, default, meaning and unit.
std::string configTable(const DetectorParams& params = {});

/// `base` with the values the JSON document sets. InputError (naming `source`) for text that
/// is not JSON, an unknown section or key (the known ones listed), a value of the wrong type
/// or out of range, and parameters that fail validateDetectorParams.
DetectorParams parseConfig(const std::string& text, const std::string& source, const DetectorParams& base = {});

/// parseConfig of a file; InputError when it is missing or unreadable.
DetectorParams loadConfig(const std::string& path, const DetectorParams& base = {});

/// `from_file` overridden by every field of `from_flags` that differs from `defaults`: what a
/// command line gives wins over the config file.
DetectorParams mergeConfig(const DetectorParams& defaults, const DetectorParams& from_file,
                           const DetectorParams& from_flags);

}  // namespace vkpose
