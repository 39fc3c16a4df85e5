#pragma once
// Wall-clock milliseconds for the per-stage timings, and the process's CPU time.
#include <chrono>
#include <ctime>

namespace vkpose::util {

inline double msSince(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

/// CPU milliseconds this process has used so far, all its threads together (the Vulkan
/// driver's too: lavapipe's workers are threads of the process).
inline double processCpuMs() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return 1e3 * static_cast<double>(ts.tv_sec) + 1e-6 * static_cast<double>(ts.tv_nsec);
}

}  // namespace vkpose::util
