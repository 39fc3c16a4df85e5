#pragma once
// Errors vkpose reports. Each is an exception whose message names the bad value and, where
// there is one, the file. The CLI turns them into one clear line and a documented exit code.
#include <stdexcept>
#include <string>

namespace vkpose {

/// Bad input from the user: a missing or corrupt file, inconsistent images, nonsense values.
/// CLI exit code 1.
class InputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// No usable Vulkan device, or the device failed. CLI exit code 3.
class DeviceError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace vkpose
