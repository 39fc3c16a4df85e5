// Stages 3 and 5: template clustering and non-maximum suppression.
#include <algorithm>
#include <bit>
#include <climits>
#include <cmath>
#include <cstdint>
#include <tuple>

#include <Eigen/Geometry>

#include "hypotheses/hypotheses.hpp"
#include "match/matcher.hpp"
#include "util/radix_sort.hpp"
#include "vkpose/bank.hpp"
#include "vkpose/config.hpp"
#include "vkpose/error.hpp"
#include "vkpose/geometry.hpp"

namespace vkpose {

TemplateIndex::TemplateIndex(const std::vector<TemplateBank>& banks) {
  first.reserve(banks.size() + 1);
  int n = 0;
  for (const auto& b : banks) {
    first.push_back(n);
    n += static_cast<int>(b.templates.size());
  }
  first.push_back(n);
}

int TemplateIndex::bankOf(int global_id) const {
  if (global_id < 0 || global_id >= first.back())
    throw InputError("template id " + std::to_string(global_id) + " is outside the banks' " +
                     std::to_string(first.back()) + " templates");
  const auto it = std::upper_bound(first.begin(), first.end() - 1, global_id);
  return static_cast<int>(it - first.begin()) - 1;
}

std::vector<LinemodTemplate> concatenateTemplates(const std::vector<TemplateBank>& banks) {
  std::vector<LinemodTemplate> all;
  for (const auto& b : banks)
    for (const auto& t : b.templates) all.push_back(t.linemod);
  return all;
}

namespace {

using Key = std::tuple<int, int, int, long>;  // bank, cell row, cell column, distance (0.1 mm)
struct Entry {
  Key key;
  ClusterMember member;
  std::size_t order;  // the match's index: among equal similarities the first wins
  int distance_slot;  // the key's distance as an index into clusterTemplates' distances
};

/// Sorts the entries by key, then template, then order: each template's matches in a key
/// are then neighbours, the first of them first. Packed into 64-bit keys (the distance as its
/// rank among the few distinct ones) and radix-sorted where they fit, which is several times
/// faster than sorting the tuples (LM-O's frame: 928,000 entries); else sorted as tuples.
void sortForGrouping(std::vector<Entry>& entries, const std::vector<long>& distances) {
  if (entries.empty()) return;
  std::vector<int> rank(distances.size());
  {
    std::vector<long> sorted = distances;
    std::sort(sorted.begin(), sorted.end());
    for (std::size_t k = 0; k < distances.size(); ++k)
      rank[k] = static_cast<int>(std::lower_bound(sorted.begin(), sorted.end(), distances[k]) - sorted.begin());
  }
  int min_r = INT32_MAX, max_r = INT32_MIN, min_c = INT32_MAX, max_c = INT32_MIN, max_b = 0, max_t = 0;
  for (const Entry& e : entries) {
    min_r = std::min(min_r, std::get<1>(e.key)), max_r = std::max(max_r, std::get<1>(e.key));
    min_c = std::min(min_c, std::get<2>(e.key)), max_c = std::max(max_c, std::get<2>(e.key));
    max_b = std::max(max_b, std::get<0>(e.key)), max_t = std::max(max_t, e.member.template_index);
  }
  auto bits = [](int64_t v) { return static_cast<int>(std::bit_width(static_cast<uint64_t>(v))); };
  const int bb = bits(max_b), br = bits(int64_t(max_r) - min_r), bc = bits(int64_t(max_c) - min_c);
  const int bd = bits(static_cast<int64_t>(distances.size()) - 1), bt = bits(max_t);
  if (!util::fitsWithIndex(bb + br + bc + bd + bt, entries.size())) {
    std::sort(entries.begin(), entries.end(), [](const Entry& a, const Entry& b) {
      if (a.key != b.key) return a.key < b.key;
      if (a.member.template_index != b.member.template_index) return a.member.template_index < b.member.template_index;
      return a.order < b.order;
    });
    return;
  }
  std::vector<uint64_t> keys(entries.size());
  for (std::size_t i = 0; i < entries.size(); ++i) {
    const Entry& e = entries[i];
    uint64_t k = static_cast<uint64_t>(std::get<0>(e.key));
    k = (k << br) | static_cast<uint64_t>(int64_t(std::get<1>(e.key)) - min_r);
    k = (k << bc) | static_cast<uint64_t>(int64_t(std::get<2>(e.key)) - min_c);
    k = (k << bd) | static_cast<uint64_t>(rank[static_cast<std::size_t>(e.distance_slot)]);
    keys[i] = (k << bt) | static_cast<uint64_t>(e.member.template_index);
  }
  std::vector<Entry> sorted;
  sorted.reserve(entries.size());
  for (const uint32_t i : util::stableOrder(keys)) sorted.push_back(entries[i]);  // entries are in match order
  entries.swap(sorted);
}

}  // namespace

std::vector<Hypothesis> clusterTemplates(const std::vector<Match>& matches, const std::vector<TemplateBank>& banks,
                                         const ClusterParams& params) {
  if (params.position_step_px < 1) throw InputError("cluster position step s_im must be at least 1 pixel");
  if (params.min_templates < 1) throw InputError("cluster size tau_c must be at least 1 template");
  const TemplateIndex index(banks);
  const float step = static_cast<float>(params.position_step_px);

  // Key: bank, cell row, cell column, training distance (whole 0.1 mm, so equal radii group
  // exactly). Per key, the best match of each template (the first of equals). Sorting one flat
  // array instead of filling a map of maps: LM-O frames bring 300,000 matches (364 -> 131 ms).
  // What a match needs of its template, by global template id, in one small table: reaching
  // each BankTemplate (a few hundred bytes apart) for every match was most of the stage.
  struct Placing {
    float anchor_x, anchor_y;
    int bank, slot;  // slot: the training distance as an index into `distances`
  };
  std::vector<Placing> placing;
  placing.reserve(static_cast<std::size_t>(index.first.back()));
  std::vector<long> distances;  // the distinct training distances (0.1 mm)
  for (std::size_t b = 0; b < banks.size(); ++b)
    for (const BankTemplate& t : banks[b].templates) {
      const long distance = std::lround(t.distance * 1e4f);
      auto slot = std::find(distances.begin(), distances.end(), distance) - distances.begin();
      if (slot == static_cast<std::ptrdiff_t>(distances.size())) distances.push_back(distance);
      placing.push_back({t.anchor_x, t.anchor_y, static_cast<int>(b), static_cast<int>(slot)});
    }
  std::vector<Entry> entries;
  entries.reserve(matches.size());
  for (std::size_t i = 0; i < matches.size(); ++i) {
    const Match& m = matches[i];
    if (m.template_id < 0 || m.template_id >= index.first.back()) index.bankOf(m.template_id);  // throws
    const Placing& p = placing[static_cast<std::size_t>(m.template_id)];
    const int local = m.template_id - index.first[static_cast<std::size_t>(p.bank)];
    ClusterMember member{local, m.x, m.y, m.similarity, static_cast<float>(m.x) + p.anchor_x,
                         static_cast<float>(m.y) + p.anchor_y};
    const Key key{p.bank, static_cast<int>(std::floor(member.centre_y / step)),
                  static_cast<int>(std::floor(member.centre_x / step)), distances[static_cast<std::size_t>(p.slot)]};
    entries.push_back({key, member, i, p.slot});
  }
  sortForGrouping(entries, distances);

  std::vector<Hypothesis> hypotheses;
  std::vector<ClusterMember> members;  // one key's, by template index
  for (std::size_t first = 0; first < entries.size();) {
    std::size_t end = first;
    members.clear();
    for (; end < entries.size() && entries[end].key == entries[first].key; ++end) {
      const ClusterMember& m = entries[end].member;
      if (members.empty() || members.back().template_index != m.template_index)
        members.push_back(m);
      else if (m.similarity > members.back().similarity)  // the template's best, first of equals
        members.back() = m;
    }
    const Key key = entries[first].key;
    first = end;
    if (static_cast<int>(members.size()) < params.min_templates) continue;
    Hypothesis h;
    h.bank = std::get<0>(key);
    h.distance = static_cast<float>(std::get<3>(key)) * 1e-4f;
    double sx = 0, sy = 0;
    for (const auto& m : members) {
      sx += m.centre_x;
      sy += m.centre_y;
      h.members.push_back(m);
    }
    h.x = static_cast<float>(sx / static_cast<double>(members.size()));
    h.y = static_cast<float>(sy / static_cast<double>(members.size()));
    std::stable_sort(h.members.begin(), h.members.end(),
                     [](const ClusterMember& a, const ClusterMember& b) { return a.similarity > b.similarity; });
    hypotheses.push_back(std::move(h));
  }
  return hypotheses;
}

float projectedDiameter(const Hypothesis& h, const std::vector<TemplateBank>& banks, double fx) {
  const float d = banks.at(static_cast<std::size_t>(h.bank)).diameter;
  return h.distance > 0.f ? static_cast<float>(fx) * d / h.distance : 0.f;
}

namespace {

/// Whether NMS lets `kept` suppress `h` (the radius suppressNonMaxima and runnersUp share).
bool withinSuppressionRadius(const Hypothesis& h, const Hypothesis& kept, const std::vector<TemplateBank>& banks,
                             double fx, const NmsParams& params) {
  // Within one small part only: across objects, one place holds one object.
  const float fraction = kept.bank == h.bank && isSmallPart(banks[static_cast<std::size_t>(h.bank)].diameter)
                             ? params.small_part_radius_fraction
                             : params.radius_fraction;
  const float r = params.radius_px > 0.f
                      ? params.radius_px
                      : fraction * std::max(projectedDiameter(h, banks, fx), projectedDiameter(kept, banks, fx));
  const float dx = h.x - kept.x, dy = h.y - kept.y;
  return dx * dx + dy * dy < r * r;
}

}  // namespace

float nmsRank(const Hypothesis& h, const std::vector<TemplateBank>& banks, const NmsParams& params) {
  if (params.template_weight == 0.f || !isSmallPart(banks[static_cast<std::size_t>(h.bank)].diameter))
    return h.score;
  return h.score * std::pow(static_cast<float>(h.members.size()), params.template_weight);
}

std::vector<Hypothesis> suppressNonMaxima(std::vector<Hypothesis> hypotheses, const std::vector<TemplateBank>& banks,
                                          double fx, const NmsParams& params) {
  if (!(params.radius_px >= 0.f) || !(params.radius_fraction > 0.f) || !(params.small_part_radius_fraction > 0.f))
    throw InputError("NMS radius must be positive (radius_px >= 0, radius_fraction > 0)");
  // Best rank first; ties broken by position so the order never depends on the input order.
  // The ranks are computed once, not per comparison.
  std::vector<std::pair<float, Hypothesis>> ranked;
  ranked.reserve(hypotheses.size());
  for (auto& h : hypotheses) {
    const float rank = nmsRank(h, banks, params);
    ranked.emplace_back(rank, std::move(h));
  }
  std::stable_sort(ranked.begin(), ranked.end(), [](const auto& a, const auto& b) {
    return std::tie(b.first, a.second.bank, a.second.y, a.second.x) <
           std::tie(a.first, b.second.bank, b.second.y, b.second.x);
  });
  std::vector<Hypothesis> kept;
  for (auto& [rank, h] : ranked) {
    bool suppressed = false;
    for (const auto& k : kept) {
      if (!params.across_objects && k.bank != h.bank) continue;
      if (withinSuppressionRadius(h, k, banks, fx, params)) {
        suppressed = true;
        break;
      }
    }
    if (!suppressed) kept.push_back(std::move(h));
  }
  return kept;
}

cv::Rect2f templateBox(const Hypothesis& h, const BankTemplate& t) {
  const float x = h.x - t.anchor_x + static_cast<float>(t.crop.x0);
  const float y = h.y - t.anchor_y + static_cast<float>(t.crop.y0);
  return {x, y, static_cast<float>((t.crop.cols - 1) * t.crop.stride + 1),
          static_cast<float>((t.crop.rows - 1) * t.crop.stride + 1)};
}

Eigen::Matrix3f viewingRayRotation(float x, float y, const Camera& camera) {
  const Eigen::Vector3f ray = camera.ray(x, y);
  return Eigen::Quaternionf::FromTwoVectors(Eigen::Vector3f::UnitZ(), ray.normalized()).toRotationMatrix();
}

std::vector<Hypothesis> runnersUp(const std::vector<Hypothesis>& all, const std::vector<Hypothesis>& kept,
                                  const std::vector<TemplateBank>& banks, double fx, const NmsParams& params) {
  if (!(params.runner_up_share > 0.f)) return {};
  const float min_angle = 30.f * static_cast<float>(M_PI) / 180.f;
  const auto bestView = [&](const Hypothesis& h) -> const Eigen::Matrix3f& {
    const auto& m = h.members[static_cast<std::size_t>(h.best_member)];
    return banks[static_cast<std::size_t>(h.bank)].templates[static_cast<std::size_t>(m.template_index)].pose.R;
  };
  // A bank of several resting poses keeps one runner-up per resting pose (that of the
  // hypothesis's best view). A cup seen straight into its opening lost to a view of its other
  // end (its rim on the foot ring, 10 cm too far), and the one runner-up was a view of it
  // lying: both fit the depth a little better than the right view, whose deep inside shifts
  // with each degree of tilt between the viewpoints.
  const auto restingPose = [&](const Hypothesis& h) {
    const TemplateBank& bank = banks[static_cast<std::size_t>(h.bank)];
    const auto& m = h.members[static_cast<std::size_t>(h.best_member)];
    const int per_pose = std::max(1, bank.params.views.viewpoints);
    return std::min(bank.templates[static_cast<std::size_t>(m.template_index)].viewpoint / per_pose,
                    static_cast<int>(bank.params.views.other_ups.size()));
  };
  std::size_t slots = 1;
  for (const TemplateBank& b : banks) slots = std::max(slots, 1 + b.params.views.other_ups.size());
  std::vector<int> best(kept.size() * slots, -1);
  for (std::size_t i = 0; i < all.size(); ++i) {
    const Hypothesis& h = all[i];
    if (h.best_member < 0 || isSmallPart(banks[static_cast<std::size_t>(h.bank)].diameter)) continue;
    // The survivor that suppressed h: the first (best) one of its object within the radius,
    // as in suppressNonMaxima. h itself, a survivor, is the first within reach of itself.
    for (std::size_t k = 0; k < kept.size(); ++k) {
      const Hypothesis& s = kept[k];
      if (s.bank != h.bank || s.best_member < 0 || !withinSuppressionRadius(h, s, banks, fx, params)) continue;
      const bool another_view = Eigen::AngleAxisf(bestView(h).transpose() * bestView(s)).angle() > min_angle;
      const int pose = restingPose(h);
      int& slot = best[k * slots + static_cast<std::size_t>(pose)];
      const float share = pose == restingPose(s) ? params.runner_up_share : params.resting_pose_runner_up_share;
      if (another_view && h.score >= share * s.score &&
          (slot < 0 || h.score > all[static_cast<std::size_t>(slot)].score))
        slot = static_cast<int>(i);
      break;
    }
  }
  std::vector<Hypothesis> out;
  for (const int i : best)
    if (i >= 0) out.push_back(all[static_cast<std::size_t>(i)]);
  return out;
}

/// Stage 5. With poses: NMS within each object, then the best few of each object (see
/// pose_min_score), objects competing after verification, in 3D; and a runner-up rides with
/// each survivor that gets a pose. Without: one hypothesis a place for all (no verification
/// removes a small part's duplicates).
std::vector<Hypothesis> nonMaximumSuppression(std::vector<Hypothesis> hypotheses, const std::vector<TemplateBank>& banks,
                                              float fx, const DetectorParams& params) {
  NmsParams nms = params.nms;
  if (!params.estimate_poses) {
    nms.small_part_radius_fraction = nms.radius_fraction;
    return suppressNonMaxima(std::move(hypotheses), banks, fx, nms);
  }
  nms.across_objects = false;
  std::vector<Hypothesis> all;  // for the runners-up
  if (nms.runner_up_share > 0.f) all = hypotheses;
  hypotheses = suppressNonMaxima(std::move(hypotheses), banks, fx, nms);
  std::vector<int> taken(banks.size(), 0);
  std::erase_if(hypotheses, [&](const Hypothesis& h) {  // best first
    const auto b = static_cast<std::size_t>(h.bank);
    const int most = isSmallPart(banks[b].diameter) ? params.small_part_pose_candidates
                                                    : params.pose_candidates_per_object;
    return taken[b]++ >= most;
  });
  for (auto& h : runnersUp(all, hypotheses, banks, fx, nms)) hypotheses.push_back(std::move(h));
  return hypotheses;
}


}  // namespace vkpose
