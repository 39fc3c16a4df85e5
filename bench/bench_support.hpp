#pragma once
// What the benchmarks share: order statistics of timings, a stopwatch, the process's peak
// resident memory, and a plain-text SVG line plot for the sweeps.
#include <chrono>
#include <cstddef>
#include <string>
#include <utility>
#include <vector>

namespace vkpose::bench {

/// The p-th percentile (p in [0, 100]) of `values` by linear interpolation between the
/// closest ranks (numpy's default): percentile({1, 2, 3, 4}, 50) = 2.5. 0 for no values.
double percentile(std::vector<double> values, double p);
inline double median(std::vector<double> values) { return percentile(std::move(values), 50.0); }

/// Milliseconds f() takes.
template <class F>
double timeMs(F&& f) {
  const auto t0 = std::chrono::steady_clock::now();
  f();
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

/// The most resident memory this process has held (VmHWM in /proc/self/status, getrusage's
/// ru_maxrss where that is missing), bytes.
std::size_t peakResidentBytes();

/// The resident memory this process holds now (VmRSS), bytes; 0 where unknown.
std::size_t residentBytes();

/// "1.5 MiB", "312 KiB", "2.03 GiB".
std::string formatBytes(std::size_t bytes);

/// One line of a plot: (x, y) points in order.
struct PlotSeries {
  std::string label;
  std::string colour;  ///< an SVG colour ("#1f77b4")
  std::vector<std::pair<double, double>> points;
};

struct PlotSpec {
  std::string title, x_label, y_label;
  bool log_y = false;  ///< x is always logarithmic
  std::vector<PlotSeries> series;
  int width = 640, height = 420;  ///< pixels
};

/// A self-contained SVG line plot: a frame with axes, ticks and grid lines at 1, 2 and 5
/// times each power of ten on the log x axis (and on y when log_y, else about 6 round
/// steps), a polyline with dots per series, the title, axis labels and a legend. Points with
/// x <= 0 (or y <= 0 on a log axis) are left out. Throws std::invalid_argument when no series
/// has a point to draw.
std::string svgLinePlot(const PlotSpec& spec);

/// The per-kernel times VKPOSE_PROFILE_KERNELS=1 gathered over the whole run (nothing when off).
void printKernelProfile();

}  // namespace vkpose::bench
