#pragma once
// Border rules of the reference kernels; shaders/common.glsl has the GLSL twins.

namespace vkpose {

/// BORDER_REPLICATE: index clamped into [0, n).
inline int clampIndex(int i, int n) { return i < 0 ? 0 : (i >= n ? n - 1 : i); }

/// BORDER_REFLECT_101 (gfedcb|abcdefgh|gfedcba): OpenCV's default border.
inline int reflect101Index(int i, int n) {
  if (n == 1) return 0;
  while (i < 0 || i >= n) i = i < 0 ? -i : 2 * n - 2 - i;
  return i;
}

}  // namespace vkpose
