#pragma once
// A one-line progress bar on stderr for long work (training, synth, eval, bench). It draws
// only when stderr is a terminal and the user did not ask for --quiet, so logs and pipes stay
// clean.
#include <chrono>
#include <cstdio>
#include <string>

#include <unistd.h>

namespace vkpose::util {

class ProgressBar {
 public:
  ProgressBar(std::string label, bool quiet) : label_(std::move(label)), enabled_(!quiet && isatty(fileno(stderr))) {}
  ~ProgressBar() { finish(); }
  ProgressBar(const ProgressBar&) = delete;
  ProgressBar& operator=(const ProgressBar&) = delete;

  void update(std::size_t done, std::size_t total) {
    if (!enabled_ || total == 0) return;
    const auto now = std::chrono::steady_clock::now();
    if (done < total && now - last_ < std::chrono::milliseconds(100)) return;  // redraw at most 10 Hz
    last_ = now;
    const double frac = static_cast<double>(done) / static_cast<double>(total);
    const int width = 30, filled = static_cast<int>(frac * width);
    const double elapsed = std::chrono::duration<double>(now - start_).count();
    const double eta = frac > 0 ? elapsed * (1 - frac) / frac : 0;
    std::fprintf(stderr, "\r%s [%s%s] %zu/%zu  %.0f%%  %.0fs left ", label_.c_str(), std::string(filled, '#').c_str(),
                 std::string(width - filled, '.').c_str(), done, total, 100 * frac, eta);
    std::fflush(stderr);
    drawn_ = true;
  }
  void finish() {
    if (drawn_) std::fprintf(stderr, "\n");
    drawn_ = false;
  }

 private:
  std::string label_;
  bool enabled_;
  bool drawn_ = false;
  std::chrono::steady_clock::time_point start_ = std::chrono::steady_clock::now(), last_{};
};

}  // namespace vkpose::util
