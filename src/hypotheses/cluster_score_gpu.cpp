// Stage 4 on the GPU: the banks' crops (once, while the same banks come back; else each
// frame's members' crops), one record per member and the scene depth go up in one batch;
// shaders/scene_normals.comp computes the scene's normals once, shaders/cluster_score.comp
// scores each member in one invocation; the member scores come back and are combined on
// the CPU.
#include <bit>
#include <cstring>
#include <string>
#include <unordered_map>

#include "gpu/batch.hpp"
#include "gpu/kernel_interface.h"
#include "hypotheses/cluster_score_math.hpp"

namespace vkpose {
namespace gpu {

/// What identifies the banks whose crops are resident: a Detector's banks never change, and
/// another set of banks differs in one of these.
struct BankIdentity {
  const BankTemplate* templates;
  std::size_t count;
  uint64_t mesh_hash;
  std::string object;
  bool operator==(const BankIdentity&) const = default;
};

class ClusterScoreKernels {
 public:
  ClusterScoreKernels(const GpuContext& c, std::size_t resident_bytes)
      : ctx(c),
        resident_crop_bytes(resident_bytes),
        normals(c, ShaderId::scene_normals, 2, sizeof(ScorePush), {}, {{0, vk::Format::eR32Uint}}),
        kernel(c, ShaderId::cluster_score, 5, sizeof(ScorePush), {},
               {{0, vk::Format::eR32G32Uint},
                {1, vk::Format::eR32G32B32A32Uint},
                {2, vk::Format::eR32Uint},
                {4, vk::Format::eR32G32B32A32Uint}}) {}
  const GpuContext& ctx;
  std::size_t resident_crop_bytes;
  Kernel normals, kernel;
  Buffer cells, members, depth, scene_normals, scores;
  // The resident crops: every template's cells in `cells` from first_cell[bank][template] on.
  std::vector<BankIdentity> resident_for;
  std::vector<std::vector<uint32_t>> first_cell;
  bool resident = false;
};

}  // namespace gpu

namespace {

/// A crop's cells as the kernel reads them: depth (0.1 mm), then the normal's three bytes.
void packCropCells(const TemplateCrop& c, uint32_t* out) {
  for (std::size_t k = 0; k < c.depth_01mm.size(); ++k) {
    uint32_t n = 0;
    for (int a = 0; a < 3; ++a) n |= static_cast<uint32_t>(static_cast<uint8_t>(c.normals[3 * k + a])) << (8 * a);
    out[2 * k] = c.depth_01mm[k];
    out[2 * k + 1] = n;
  }
}

std::vector<gpu::BankIdentity> identify(const std::vector<TemplateBank>& banks) {
  std::vector<gpu::BankIdentity> ids;
  for (const auto& b : banks) ids.push_back({b.templates.data(), b.templates.size(), b.mesh_hash, b.object});
  return ids;
}

/// Lays every template of `banks` out in g.cells and uploads them all, when they fit the
/// budget and one texel-buffer binding; otherwise leaves g.resident false.
void makeCropsResident(gpu::ClusterScoreKernels& g, const std::vector<TemplateBank>& banks, gpu::Batch& batch) {
  g.resident_for = identify(banks);
  g.first_cell.assign(banks.size(), {});
  std::size_t cells = 0;
  for (std::size_t b = 0; b < banks.size(); ++b)
    for (const auto& t : banks[b].templates) {
      g.first_cell[b].push_back(static_cast<uint32_t>(std::min<std::size_t>(cells, UINT32_MAX)));
      cells += t.crop.depth_01mm.size();
    }
  const auto& dev = g.ctx.device();
  // The kernel reads the cells as a texel buffer of 8-byte texels (its binding's limit).
  g.resident = cells > 0 && cells * 8 <= g.resident_crop_bytes && cells <= dev.max_texel_buffer_elements;
  if (!g.resident) return;
  g.cells.reserve(g.ctx, cells * 8);
  auto* out = static_cast<uint32_t*>(batch.uploadInPlace(g.cells, cells * 8));
  for (std::size_t b = 0; b < banks.size(); ++b)
    for (std::size_t t = 0; t < banks[b].templates.size(); ++t)
      packCropCells(banks[b].templates[t].crop, out + 2 * std::size_t(g.first_cell[b][t]));
}

}  // namespace

ClusterScorer::ClusterScorer(const GpuContext& ctx, std::size_t resident_crop_bytes)
    : gpu_(std::make_unique<gpu::ClusterScoreKernels>(ctx, resident_crop_bytes)) {}
ClusterScorer::~ClusterScorer() = default;

void ClusterScorer::score(std::vector<Hypothesis>& hypotheses, const std::vector<TemplateBank>& banks,
                          const ScoreScene& scene, const ScoreParams& params) {
  scoreMembers(hypotheses, banks, scene, params);
  combineMemberScores(hypotheses, params);
}

void ClusterScorer::scoreMembers(std::vector<Hypothesis>& hypotheses, const std::vector<TemplateBank>& banks,
                                 const ScoreScene& scene, const ScoreParams& params) {
  validateScoreParams(params);
  auto& g = *gpu_;
  gpu::Batch batch(g.ctx);
  if (g.resident_for != identify(banks)) makeCropsResident(g, banks, batch);
  // Without resident crops each distinct template's crop goes up once a frame, however
  // many hypotheses hold it.
  std::vector<uint32_t> cells;  // 2 words per cell
  std::unordered_map<uint64_t, uint32_t> first_cell;
  std::vector<uint32_t> records;  // 16 words per member
  for (auto& h : hypotheses) {
    const auto& bank = banks.at(static_cast<std::size_t>(h.bank));
    const Eigen::Matrix3f ray = viewingRayRotation(h.x, h.y, scene.camera);
    h.member_scores.assign(score::scoredMembers(h, params), {});
    for (std::size_t m = 0; m < h.member_scores.size(); ++m) {
      const int ti = h.members[m].template_index;
      const BankTemplate& t = bank.templates.at(static_cast<std::size_t>(ti));
      uint32_t cell0 = 0;
      if (g.resident) {
        cell0 = g.first_cell[static_cast<std::size_t>(h.bank)][static_cast<std::size_t>(ti)];
      } else {
        const uint64_t key = (static_cast<uint64_t>(h.bank) << 32) | static_cast<uint32_t>(ti);
        auto [it, inserted] = first_cell.try_emplace(key, static_cast<uint32_t>(cells.size() / 2));
        if (inserted) {
          cells.resize(cells.size() + 2 * t.crop.depth_01mm.size());
          packCropCells(t.crop, cells.data() + 2 * std::size_t(it->second));
        }
        cell0 = it->second;
      }
      const score::MemberPlacement at = score::placeMember(h, t);
      auto f = [](float v) { return std::bit_cast<uint32_t>(v); };
      const uint32_t record[16] = {cell0,
                                   static_cast<uint32_t>(t.crop.cols) | (static_cast<uint32_t>(t.crop.rows) << 16),
                                   static_cast<uint32_t>(t.crop.stride), 0u,
                                   static_cast<uint32_t>(at.x0), static_cast<uint32_t>(at.y0), f(ray(0, 0)), f(ray(0, 1)),
                                   f(ray(0, 2)), f(ray(1, 0)), f(ray(1, 1)), f(ray(1, 2)),
                                   f(ray(2, 0)), f(ray(2, 1)), f(ray(2, 2)), 0u};
      records.insert(records.end(), std::begin(record), std::end(record));
    }
  }
  const std::size_t member_count = records.size() / 16;
  if (member_count == 0) {
    batch.submit();  // the resident crops, if they went up now
    return;
  }

  const cv::Mat& depth = scene.depth_m;
  CV_Assert(depth.type() == CV_32FC1 && depth.isContinuous());
  if (!g.resident) g.cells.reserve(g.ctx, cells.size() * 4);
  g.members.reserve(g.ctx, records.size() * 4);
  g.depth.reserve(g.ctx, depth.total() * 4);
  g.scene_normals.reserve(g.ctx, depth.total() * 16);
  g.scores.reserve(g.ctx, member_count * 32);
  if (!g.resident) batch.upload(g.cells, cells.data(), cells.size() * 4);
  batch.upload(g.members, records.data(), records.size() * 4);
  batch.upload(g.depth, depth.data, depth.total() * 4);
  const gpu::ScorePush push{scene.camera.floatIntrinsics(), depth.cols, depth.rows, static_cast<uint32_t>(member_count),
                            params.normal_step_px, params.normal_max_jump_m, params.depth_cap_m};
  // The scene's normals once for all members (scene_normals.comp), then the members.
  const auto pixel_groups = gpu::groups2DFor(depth.total(), gpu::kWorkgroupSize);
  batch.dispatch(g.normals, {g.depth, g.scene_normals}, push, pixel_groups.x, pixel_groups.y);
  const auto groups = gpu::groups2DFor(member_count, gpu::kWorkgroupSize);
  batch.dispatch(g.kernel, {g.cells, g.members, g.depth, g.scores, g.scene_normals}, push, groups.x, groups.y);
  std::vector<uint32_t> out(member_count * 8);
  batch.download(g.scores, out.data(), out.size() * 4);
  batch.submit();

  std::size_t m = 0;
  for (auto& h : hypotheses)
    for (auto& s : h.member_scores) {
      const uint32_t* o = &out[8 * m++];
      s.object_cells = static_cast<int>(o[0]);
      s.depth_pairs = static_cast<int>(o[1]);
      s.normal_pairs = static_cast<int>(o[2]);
      s.depth_offset = std::bit_cast<float>(o[4]);
      s.depth_error = std::bit_cast<float>(o[5]);
      s.angle_error = std::bit_cast<float>(o[6]);
    }
}

}  // namespace vkpose
