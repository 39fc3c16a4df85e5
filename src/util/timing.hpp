#pragma once
// Wall-clock milliseconds for the per-stage timings.
#include <chrono>

namespace vkpose::util {

inline double msSince(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

}  // namespace vkpose::util
