#include "bench/bench_support.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <limits>
#include <stdexcept>

#include <fmt/core.h>
#include <fmt/format.h>
#include <sys/resource.h>

#include "gpu/batch.hpp"

namespace vkpose::bench {

double percentile(std::vector<double> v, double p) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  const double rank = std::clamp(p, 0.0, 100.0) / 100.0 * static_cast<double>(v.size() - 1);
  const auto lo = static_cast<std::size_t>(std::floor(rank));
  const std::size_t hi = std::min(lo + 1, v.size() - 1);
  return v[lo] + (rank - static_cast<double>(lo)) * (v[hi] - v[lo]);
}

namespace {
/// A "Name:  N kB" line of /proc/self/status, bytes; 0 when it is not there.
std::size_t statusBytes(const std::string& name) {
  std::ifstream status("/proc/self/status");
  for (std::string line; std::getline(status, line);)
    if (line.rfind(name + ":", 0) == 0) return static_cast<std::size_t>(std::stoull(line.substr(name.size() + 1))) * 1024;
  return 0;
}
}  // namespace

std::size_t residentBytes() { return statusBytes("VmRSS"); }

std::size_t peakResidentBytes() {
  // The kernel updates VmHWM lazily: it can lag VmRSS by a few pages.
  if (const std::size_t hwm = statusBytes("VmHWM")) return std::max(hwm, residentBytes());
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return static_cast<std::size_t>(usage.ru_maxrss) * 1024;  // kilobytes on Linux
}

std::string formatBytes(std::size_t bytes) {
  const double b = static_cast<double>(bytes);
  if (b >= 1024.0 * 1024 * 1024) return fmt::format("{:.2f} GiB", b / (1024.0 * 1024 * 1024));
  if (b >= 1024.0 * 1024) return fmt::format("{:.1f} MiB", b / (1024.0 * 1024));
  if (b >= 1024.0) return fmt::format("{:.0f} KiB", b / 1024.0);
  return fmt::format("{} B", bytes);
}

namespace {

/// Ticks at 1, 2 and 5 times the powers of ten within [lo, hi] (positive).
std::vector<double> logTicks(double lo, double hi) {
  std::vector<double> ticks;
  for (int e = static_cast<int>(std::floor(std::log10(lo))); e <= static_cast<int>(std::ceil(std::log10(hi))); ++e)
    for (const double m : {1.0, 2.0, 5.0}) {
      const double t = m * std::pow(10.0, e);
      if (t >= lo * (1 - 1e-9) && t <= hi * (1 + 1e-9)) ticks.push_back(t);
    }
  return ticks;
}

/// About six round steps (1, 2 or 5 times a power of ten) from 0 or below lo to hi.
std::vector<double> linearTicks(double& lo, double& hi) {
  const double raw = (hi - lo) / 6.0;
  const double mag = std::pow(10.0, std::floor(std::log10(raw)));
  const double step = raw / mag < 1.5 ? mag : raw / mag < 3.5 ? 2 * mag : raw / mag < 7.5 ? 5 * mag : 10 * mag;
  lo = std::floor(lo / step) * step;
  hi = std::ceil(hi / step) * step;
  std::vector<double> ticks;
  for (double t = lo; t <= hi + step * 1e-6; t += step) ticks.push_back(std::abs(t) < step * 1e-9 ? 0.0 : t);
  return ticks;
}

/// "100", "3k", "280k", "1.5M", "0.2".
std::string tickLabel(double v) {
  const double a = std::abs(v);
  if (a >= 1e6) return fmt::format("{:g}M", v / 1e6);
  if (a >= 1e3) return fmt::format("{:g}k", v / 1e3);
  return fmt::format("{:g}", v);
}

std::string escapeXml(const std::string& s) {
  std::string out;
  for (const char c : s) {
    switch (c) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      default: out += c;
    }
  }
  return out;
}

}  // namespace

std::string svgLinePlot(const PlotSpec& spec) {
  double x0 = std::numeric_limits<double>::infinity(), x1 = -x0, y0 = x0, y1 = -x0;
  auto usable = [&](const std::pair<double, double>& p) {
    return p.first > 0 && std::isfinite(p.first) && std::isfinite(p.second) && (!spec.log_y || p.second > 0);
  };
  for (const auto& s : spec.series)
    for (const auto& p : s.points)
      if (usable(p)) {
        x0 = std::min(x0, p.first), x1 = std::max(x1, p.first);
        y0 = std::min(y0, p.second), y1 = std::max(y1, p.second);
      }
  if (!(x0 <= x1)) throw std::invalid_argument("svgLinePlot: no point to draw");
  // Axis ranges: whole decades in log, round steps from 0 in linear.
  x0 = std::pow(10.0, std::floor(std::log10(x0)));
  x1 = std::pow(10.0, std::ceil(std::log10(x1)));
  if (x1 <= x0) x1 = x0 * 10;
  std::vector<double> yticks;
  if (spec.log_y) {
    y0 = std::pow(10.0, std::floor(std::log10(y0)));
    y1 = std::pow(10.0, std::ceil(std::log10(y1)));
    if (y1 <= y0) y1 = y0 * 10;
    yticks = logTicks(y0, y1);
  } else {
    y0 = std::min(0.0, y0);
    if (y1 <= y0) y1 = y0 + 1;
    yticks = linearTicks(y0, y1);
  }
  const double left = 80, right = 20, top = 40, bottom = 60;
  const double pw = spec.width - left - right, ph = spec.height - top - bottom;
  auto px = [&](double x) { return left + (std::log10(x) - std::log10(x0)) / (std::log10(x1) - std::log10(x0)) * pw; };
  auto py = [&](double y) {
    const double f = spec.log_y ? (std::log10(y) - std::log10(y0)) / (std::log10(y1) - std::log10(y0)) : (y - y0) / (y1 - y0);
    return top + (1 - f) * ph;
  };

  std::string svg = fmt::format(
      "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{0}\" height=\"{1}\" viewBox=\"0 0 {0} {1}\" "
      "font-family=\"sans-serif\" font-size=\"12\">\n"
      "<rect width=\"{0}\" height=\"{1}\" fill=\"white\"/>\n"
      "<text x=\"{2}\" y=\"22\" text-anchor=\"middle\" font-size=\"14\">{3}</text>\n",
      spec.width, spec.height, left + pw / 2, escapeXml(spec.title));
  for (const double t : logTicks(x0, x1)) {
    const double x = px(t);
    svg += fmt::format("<line x1=\"{0:.1f}\" y1=\"{1:.1f}\" x2=\"{0:.1f}\" y2=\"{2:.1f}\" stroke=\"#ddd\"/>\n", x, top,
                       top + ph);
    svg += fmt::format("<text x=\"{:.1f}\" y=\"{:.1f}\" text-anchor=\"middle\">{}</text>\n", x, top + ph + 16,
                       tickLabel(t));
  }
  for (const double t : yticks) {
    const double y = py(t);
    svg += fmt::format("<line x1=\"{0:.1f}\" y1=\"{1:.1f}\" x2=\"{2:.1f}\" y2=\"{1:.1f}\" stroke=\"#ddd\"/>\n", left, y,
                       left + pw);
    svg += fmt::format("<text x=\"{:.1f}\" y=\"{:.1f}\" text-anchor=\"end\">{}</text>\n", left - 6, y + 4, tickLabel(t));
  }
  svg += fmt::format("<rect x=\"{}\" y=\"{}\" width=\"{}\" height=\"{}\" fill=\"none\" stroke=\"black\"/>\n", left, top,
                     pw, ph);
  svg += fmt::format("<text x=\"{:.1f}\" y=\"{:.1f}\" text-anchor=\"middle\">{}</text>\n", left + pw / 2,
                     spec.height - 16.0, escapeXml(spec.x_label + " (log scale)"));
  svg += fmt::format("<text transform=\"translate(18 {:.1f}) rotate(-90)\" text-anchor=\"middle\">{}</text>\n",
                     top + ph / 2, escapeXml(spec.y_label + (spec.log_y ? " (log scale)" : "")));
  for (std::size_t i = 0; i < spec.series.size(); ++i) {
    const PlotSeries& s = spec.series[i];
    std::string points;
    std::string dots;
    for (const auto& p : s.points) {
      if (!usable(p)) continue;
      points += fmt::format("{}{:.1f},{:.1f}", points.empty() ? "" : " ", px(p.first), py(p.second));
      dots += fmt::format("<circle cx=\"{:.1f}\" cy=\"{:.1f}\" r=\"3\" fill=\"{}\"/>\n", px(p.first), py(p.second),
                          s.colour);
    }
    if (!points.empty())
      svg += fmt::format("<polyline fill=\"none\" stroke=\"{}\" stroke-width=\"2\" points=\"{}\"/>\n", s.colour, points);
    svg += dots;
    const double ly = top + 14 + 18.0 * static_cast<double>(i);
    svg += fmt::format("<line x1=\"{0:.1f}\" y1=\"{1:.1f}\" x2=\"{2:.1f}\" y2=\"{1:.1f}\" stroke=\"{3}\" "
                       "stroke-width=\"2\"/>\n",
                       left + 10, ly, left + 30, s.colour);
    svg += fmt::format("<text x=\"{:.1f}\" y=\"{:.1f}\">{}</text>\n", left + 36, ly + 4, escapeXml(s.label));
  }
  svg += "</svg>\n";
  return svg;
}

void printKernelProfile() {
  if (gpu::kernelProfile().empty()) return;
  fmt::print("\nper kernel, all runs (VKPOSE_PROFILE_KERNELS; a submit per dispatch, so slower than a frame):\n");
  for (const auto& [name, ms] : gpu::kernelProfile()) fmt::print("  {:<24} {:10.2f} ms\n", name, ms);
}

}  // namespace vkpose::bench
