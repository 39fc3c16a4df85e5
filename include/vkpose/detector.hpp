#pragma once
// The detector facade: chains the stages (features and similarity on the GPU, clustering,
// cluster score, NMS) for several objects at once and records the time of each stage. It
// owns no algorithm of its own; every stage is callable alone (hypotheses.hpp,
// cluster_score.hpp, matcher.hpp).
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "vkpose/cluster_score.hpp"
#include "vkpose/hypotheses.hpp"
#include "vkpose/matcher.hpp"
#include "vkpose/template_bank.hpp"

namespace vkpose {

struct DetectorParams {
  MatchParams match;
  ClusterParams cluster;
  ScoreParams score;
  NmsParams nms;
  /// Hypotheses whose cluster score gamma is below this are dropped before NMS (a cluster on
  /// clutter, a template that fits the colour edges but not the depth).
  float min_score = 0.15f;
};

/// One detected object instance.
struct Detection {
  int bank = 0;
  std::string object;         ///< the bank's object name
  float score = 0.f;          ///< gamma
  float alpha = 0.f, beta = 0.f;
  float x = 0.f, y = 0.f;     ///< image position of the object's centre
  cv::Rect2f bbox;            ///< pixels: the best template's object box
  Pose pose;                  ///< the best template's pose, turned onto the viewing ray
  int templates = 0;          ///< members of the cluster
  int template_index = -1;    ///< the best template (within the bank)
  float similarity = 0.f;     ///< its LINEMOD similarity, percent
};

/// Milliseconds per stage, in pipeline order.
using StageTimings = std::vector<std::pair<std::string, double>>;

struct DetectionResult {
  std::vector<Detection> detections;  ///< best score first
  StageTimings timings_ms;
  std::size_t matches = 0, hypotheses = 0, scored_hypotheses = 0;  ///< counts after stages 2, 3, 4
  std::vector<std::string> warnings;  ///< e.g. a bank trained for another focal length
};

class Detector {
 public:
  /// The banks must share the feature parameters (pyramid, modalities) of the first.
  Detector(GpuContext& ctx, std::vector<TemplateBank> banks, DetectorParams params = {});
  ~Detector();
  Detector(const Detector&) = delete;
  Detector& operator=(const Detector&) = delete;

  /// Throws InputError for a frame with no depth or a camera whose principal point lies
  /// outside it (the image size is the frame's).
  DetectionResult detect(const LinemodFrame& frame, const Camera& camera);

  const std::vector<TemplateBank>& banks() const { return banks_; }
  const DetectorParams& params() const { return params_; }

 private:
  GpuContext& ctx_;
  std::vector<TemplateBank> banks_;
  DetectorParams params_;
  std::unique_ptr<LinemodMatcher> matcher_;
  std::unique_ptr<ClusterScorer> scorer_;
};

/// The pose a hypothesis's template implies: the template's rotation turned onto the viewing
/// ray through the hypothesis centre, at the template's distance moved by the member's mean
/// depth offset.
Pose templatePose(const Hypothesis& h, const MemberScore& s, const BankTemplate& t, const TemplateBank& bank,
                  const Camera& camera);

}  // namespace vkpose
