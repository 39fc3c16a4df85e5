// The camera's checks (geometry.hpp): every layer that takes a Camera, from the rasterizer up,
// refuses a nonsense one with the same words, so they live below all of them.
#include <cmath>

#include <fmt/format.h>

#include "vkpose/error.hpp"
#include "vkpose/geometry.hpp"

namespace vkpose {

void validateCamera(const Camera& c, const std::string& source) {
  auto bad = [&](const std::string& what) { throw InputError(fmt::format("{}: {}", source, what)); };
  const double fx = c.fx, fy = c.fy;
  if (!(std::isfinite(fx) && std::isfinite(fy) && fx > 0 && fy > 0))
    bad(fmt::format("focal lengths must be positive (fx {}, fy {})", fx, fy));
  if (!(std::isfinite(c.cx) && std::isfinite(c.cy))) bad("the principal point is not finite");
  if (c.width < 1 || c.height < 1 || c.width > 16384 || c.height > 16384)
    bad(fmt::format("image size {}x{} is outside 1..16384", c.width, c.height));
  if (!(std::isfinite(c.depth_scale) && c.depth_scale > 0)) bad(fmt::format("depth_scale {} must be positive", c.depth_scale));
}

}  // namespace vkpose
