#include "match/similarity_gpu.hpp"

#include <cstring>

#include "match/frame_features_gpu.hpp"
#include "vkpose/error.hpp"

namespace vkpose::gpu {

namespace {
constexpr int kHeaderInts = 6;
struct CoarsePush {
  int32_t template_base, columns, rows, stride, blocks;
  uint32_t capacity;
};
struct RefinePush {
  int32_t template_base, template_count, T_coarse, T_fine, stride;
  uint32_t capacity;
};
}  // namespace

struct Similarity::Kernels {
  explicit Kernels(const GpuContext& c)
      : coarse(c, ShaderId::similarity_coarse, 4, sizeof(CoarsePush), {}, {{0, vk::Format::eR32G32B32A32Uint}}),
        args(c, ShaderId::refine_args, 2, 4),
        refine(c, ShaderId::similarity_refine, 5, sizeof(RefinePush), {}, {{0, vk::Format::eR32G32B32A32Uint}}) {}
  Kernel coarse, args, refine;
};

Similarity::Similarity(const GpuContext& ctx) : ctx_(ctx), kernels_(std::make_unique<Kernels>(ctx)) {}
Similarity::~Similarity() = default;

void Similarity::setTemplates(Batch& batch, const std::vector<LinemodTemplate>& templates, const FeatureParams& fp,
                              const MatchParams& params, const std::vector<LinearMemoryLayout>& layouts) {
  feature_params_ = fp;
  layouts_ = layouts;
  chunks_.clear();
  const std::size_t levels = layouts.size();
  // Chunks: at most 65535 templates (workgroup rows) and features that fit one binding.
  const std::size_t max_bytes = std::min<std::size_t>(ctx_.device().max_storage_buffer_range, 64u << 20);
  std::size_t t = 0;
  while (t < templates.size()) {
    Chunk chunk;
    chunk.first_template = static_cast<int>(t);
    std::vector<int32_t> headers[2], offsets[2];
    while (t < templates.size() && chunk.template_count < 65535) {
      std::size_t add = 0;
      for (const auto& level : templates[t].levels) add += level.features.size() * 4;
      if (chunk.template_count > 0 && (offsets[0].size() + offsets[1].size()) * 4 + add > max_bytes) break;
      for (std::size_t l = 0; l < levels; ++l) {
        const auto& level = templates[t].levels[l];
        const auto& layout = layouts[l];
        const auto range = match::coarseRange(level, layout);
        const int n = static_cast<int>(level.features.size());
        headers[l].insert(headers[l].end(), {static_cast<int32_t>(offsets[l].size()), n, range.c_lo, range.r_lo,
                                             match::rawThreshold(n, params.threshold), 0});
        const int T = layout.T;
        for (const auto& f : level.features)
          offsets[l].push_back(static_cast<int32_t>(
              layout.offset(static_cast<int>(f.modality), f.bin, f.y % T, f.x % T, f.y / T, f.x / T)));
      }
      ++chunk.template_count;
      ++t;
    }
    for (std::size_t l = 0; l < levels; ++l) {
      chunk.headers[l] = Buffer(ctx_, headers[l].size() * 4);
      chunk.offsets[l] = Buffer(ctx_, offsets[l].size() * 4);
      batch.upload(chunk.headers[l], headers[l].data(), headers[l].size() * 4);
      batch.upload(chunk.offsets[l], offsets[l].data(), offsets[l].size() * 4);
    }
    chunks_.push_back(std::move(chunk));
  }
}

void Similarity::record(Batch& batch, const FrameFeatures& features) {
  const std::size_t coarse = layouts_.size() - 1;
  const auto& cl = layouts_[coarse];
  candidates_.reserve(ctx_, 16 + static_cast<std::size_t>(capacity_) * 16, MemoryKind::HostVisible);
  results_.reserve(ctx_, static_cast<std::size_t>(capacity_) * 8, MemoryKind::HostVisible);
  args_.reserve(ctx_, 16);
  batch.fill(candidates_, 0u, 16);
  const int blocks = (cl.cells_x + match::kRefineWindow - 1) / match::kRefineWindow;
  for (const auto& chunk : chunks_) {
    const CoarsePush push{chunk.first_template, cl.cells_x, cl.cells_y, cl.stride, blocks, capacity_};
    batch.dispatch(kernels_->coarse, {features.memory(coarse), chunk.headers[coarse], chunk.offsets[coarse], candidates_},
                   push, groupsFor(static_cast<std::size_t>(cl.cells_y * blocks), 64),
                   static_cast<uint32_t>(chunk.template_count));
  }
  if (coarse == 0) return;
  batch.dispatch(kernels_->args, {candidates_, args_}, capacity_, 1);
  const auto& fl = layouts_[0];
  for (const auto& chunk : chunks_) {
    const RefinePush push{chunk.first_template, chunk.template_count, cl.T, fl.T, fl.stride, capacity_};
    batch.dispatchIndirect(kernels_->refine,
                           {features.memory(0), chunk.headers[0], chunk.offsets[0], candidates_, results_}, push, args_);
  }
}

bool Similarity::read(std::vector<match::CoarseCandidate>& candidates, std::vector<match::RefineResult>& refined) {
  const auto* words = static_cast<const uint32_t*>(candidates_.mapped());
  const uint32_t count = words[0];
  candidates.clear();
  refined.clear();
  if (count > capacity_) {
    capacity_ = std::max(count + count / 4, capacity_ * 2);
    return false;
  }
  candidates.resize(count);
  for (uint32_t i = 0; i < count; ++i) {
    const uint32_t* item = words + 4 + 4 * i;
    candidates[i] = {static_cast<int>(item[0]), static_cast<int32_t>(item[1]), static_cast<int32_t>(item[2]),
                     static_cast<int>(item[3])};
  }
  if (layouts_.size() > 1) {
    const auto* res = static_cast<const uint32_t*>(results_.mapped());
    refined.resize(count);
    for (uint32_t i = 0; i < count; ++i)
      refined[i] = {static_cast<int>(res[2 * i]), static_cast<int>(res[2 * i + 1] >> 8),
                    static_cast<int>(res[2 * i + 1] & 0xFF)};
  }
  // The device appends in no fixed order; the host sorts (finishMatches) for determinism.
  return true;
}

}  // namespace vkpose::gpu
