#pragma once
// Helpers of the per-frame flow that tests and the baselines share.
#include <chrono>
#include <string>
#include <utility>
#include <vector>

#include "gpu/batch.hpp"
#include "hypotheses/cluster_score.hpp"
#include "match/matcher.hpp"
#include "util/timing.hpp"
#include "vkpose/detector.hpp"

namespace vkpose {

/// Checks a frame and its camera for detection and returns the camera with the frame's size
/// (scene_camera.json entries carry none). Throws InputError for a bad frame (validateFrame), a
/// bad camera, or a principal point outside the frame (intrinsics of another camera).
Camera frameCamera(const LinemodFrame& frame, const Camera& camera, const FeatureParams& features);

/// The pose a hypothesis's template implies: the template's rotation turned onto the viewing
/// ray through the hypothesis centre, at the template's distance moved by the member's mean
/// depth offset.
Pose templatePose(const Hypothesis& h, const MemberScore& s, const BankTemplate& t, const TemplateBank& bank,
                  const Camera& camera);

/// Stages 1-2's times under the names the detection JSON reports them by: "upload" (when the
/// templates were uploaded), "features", "similarity", "match_readback", and the GPU's share
/// of the first two in kernel_ms.
void appendMatchTimings(const MatchTimings& timings, DetectionResult& to);

/// A warning for each bank trained for another focal length than the camera's (by over 10 %).
std::vector<std::string> focalLengthWarnings(const std::vector<TemplateBank>& banks, const Camera& camera);

/// Without stages 6-8: each hypothesis at its best template's pose (templatePose).
std::vector<Detection> templateDetections(const std::vector<Hypothesis>& hypotheses,
                                          const std::vector<TemplateBank>& banks, const Camera& camera);

/// A stage's wall time and the GPU's own time within it (the device time of the submits
/// waited for meanwhile), added to the result when the stage ends: the rest is the host's.
class StageClock {
 public:
  explicit StageClock(const GpuContext& ctx) : ctx_(ctx) { restart(); }
  void restart() {
    wall0_ = std::chrono::steady_clock::now();
    device0_ = gpu::deviceMilliseconds(ctx_);
  }
  /// Wall and device milliseconds since the last restart; restarts.
  std::pair<double, double> split() {
    const std::pair<double, double> ms{util::msSince(wall0_), gpu::deviceMilliseconds(ctx_) - device0_};
    restart();
    return ms;
  }
  /// Ends the stage (less `less` wall and device ms spent in a stage timed inside it, as
  /// split() gave them) and starts the next.
  void end(Stage stage, DetectionResult& r, std::pair<double, double> less = {0, 0}) {
    const auto [wall, device] = split();
    addStage(r.timings_ms, stage, wall - less.first);
    addStage(r.kernel_ms, stage, device - less.second);
  }

 private:
  const GpuContext& ctx_;
  std::chrono::steady_clock::time_point wall0_;
  double device0_ = 0;
};


}  // namespace vkpose
