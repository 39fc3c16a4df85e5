#include "vkpose/vkpose.hpp"

namespace vkpose {

std::string version() { return VKPOSE_VERSION; }

}  // namespace vkpose
