#pragma once
// Reading RGB-D frames from files, with clear errors for everything a user can get wrong.
#include <string>

#include "vkpose/features.hpp"

namespace vkpose {

/// Loads a colour PNG/JPEG (8-bit, 3 channels; grey is expanded) and a 16-bit depth PNG.
/// depth_scale: millimetres per depth unit (BOP's `depth_scale`); depth is converted to mm.
/// Throws InputError naming the file when one is missing, unreadable, of the wrong bit depth,
/// or when the two differ in size.
LinemodFrame loadFrame(const std::string& rgb_path, const std::string& depth_path, double depth_scale = 1.0);

}  // namespace vkpose
