#include "match/similarity_gpu.hpp"

#include <cstdlib>
#include <cstring>
#include <iterator>

#include "gpu/kernel_interface.h"
#include "match/frame_features_gpu.hpp"
#include "vkpose/error.hpp"

namespace vkpose::gpu {

namespace {
// The kernels' constants and push constants (kUnitBand, kMaxSpan, UnitGrid, CoarsePush, ...)
// are gpu/kernel_interface.h's, shared with the shaders.
static_assert(kCoarseRows == match::kStripRows && 16 * kCoarseSpan == match::kStripColumns,
              "depth pruning skips what one coarse invocation scores");
constexpr std::size_t kFirstCandidatesPerTemplate = 32;  // candidates and refined: 32 bytes each
constexpr std::size_t kUnitScoreBytes = 32 * kUnitBand;  // 16 packed 16-bit scores per row
// State buffer (REFINE_STATE in refine_grid.glsl): unit count, most units of a chunk, next
// and this chunk's first candidate, the indirect dispatch sizes over the chunk's candidates
// and over its runs of each length, then the run counts.
constexpr std::size_t kCandidateArgs = 16, kRunArgs = 32, kRunCounts = kRunArgs + 16 * kMaxSpan,
                      kStateBytes = kRunCounts + 4 * kMaxSpan;
// Run list entries (runs of `span` units take `span` unit slots each): runRegion in
// refine_grid.glsl.
std::size_t runListEntries(uint32_t unit_capacity) {
  std::size_t entries = 0;
  for (uint32_t span = 1; span <= kMaxSpan; ++span) entries += unit_capacity / span;
  return entries;
}

// Blocks of a band (refine_grid.glsl): from the band's first marked column on, at most
// stride / 16 of them, as the stride is a multiple of 16.
UnitGrid unitGrid(const LinearMemoryLayout& coarse, const LinearMemoryLayout& fine) {
  return {coarse.T, fine.T, fine.pad, (fine.rows + kUnitBand - 1) / kUnitBand,
          (fine.stride / match::kRefineWindow + 31) / 32, (fine.stride + 31) / 32};
}

/// Appends a template's header (kHeaderInts ints) and feature offsets of each level to those
/// of its chunk; returns its coarse range (only the coarse level, the last, scans a range;
/// the finer one scores the units of refinement).
match::CoarseRange appendTemplate(const LinemodTemplate& tmpl, const std::vector<LinearMemoryLayout>& layouts,
                                  const MatchParams& params, const match::TemplateDepthGate& gate,
                                  std::vector<int32_t> (&headers)[2], std::vector<int32_t> (&offsets)[2]) {
  const std::size_t levels = layouts.size();
  match::CoarseRange coarse;
  for (std::size_t l = 0; l < levels; ++l) {
    const auto& level = tmpl.levels[l];
    const auto& layout = layouts[l];
    const int n = static_cast<int>(level.features.size());
    // The coarse level's threshold (similarity_coarse.comp) and, with refinement, the finer
    // level's least passing score (refine_select.comp).
    const int threshold = l == 0 && levels > 1 ? match::refinedPassScore(n, params.threshold)
                                               : match::rawThreshold(n, params.threshold);
    const auto range = l + 1 == levels ? match::coarseRange(level, layout, threshold, params.outside_response)
                                       : match::CoarseRange{};
    const int32_t header[] = {static_cast<int32_t>(offsets[l].size()), n, range.c_lo, range.r_lo,
                              threshold, range.columns, range.rows, gate.anchor_dc, gate.anchor_dr,
                              gate.z_lo_mm, gate.z_hi_mm, gate.band};
    static_assert(std::size(header) == kHeaderInts, "similarity_common.glsl reads kHeaderInts ints a template");
    headers[l].insert(headers[l].end(), std::begin(header), std::end(header));
    if (l + 1 == levels) coarse = range;
    const int T = layout.T;
    for (const auto& f : level.features)
      offsets[l].push_back(static_cast<int32_t>(
          layout.offset(static_cast<int>(f.modality), f.bin, f.y % T, f.x % T, f.y / T, f.x / T)));
  }
  return coarse;
}

}  // namespace

struct Similarity::Kernels {
  explicit Kernels(const GpuContext& c)
      : coarse(c, ShaderId::similarity_coarse, 5, sizeof(CoarsePush), {}, kCoarseTexels),
        mark(c, ShaderId::refine_mark, 4, sizeof(ChunkPush)),
        units(c, ShaderId::refine_units, 7, sizeof(UnitsPush)),
        args(c, ShaderId::refine_args, 2, sizeof(ArgsPush)),
        select(c, ShaderId::refine_select, 8, sizeof(SelectPush), {},
               {{0, vk::Format::eR32Uint},
                {1, vk::Format::eR32Uint},
                {2, vk::Format::eR32G32B32A32Uint},
                {6, vk::Format::eR32Uint},
                {7, vk::Format::eR32Sint}}) {
    for (uint32_t span = 1; span <= kMaxSpan; ++span)
      refine.push_back(std::make_unique<Kernel>(c, ShaderId::similarity_refine, 6, sizeof(RefinePush),
                                                std::vector<uint32_t>{span}, kMemoryAndOffsets));
  }
  // Linear memory, template headers and feature offsets are read as texel buffers
  // (similarity_common.glsl).
  static inline const std::vector<TexelBinding> kMemoryAndOffsets{
      {0, vk::Format::eR32G32B32A32Uint}, {1, vk::Format::eR32Sint}, {2, vk::Format::eR32Sint}};
  // The coarse pass also reads the frame's anchor cells (depth-guided pruning) as r32ui.
  static inline const std::vector<TexelBinding> kCoarseTexels{kMemoryAndOffsets[0], kMemoryAndOffsets[1],
                                                              kMemoryAndOffsets[2], {4, vk::Format::eR32Uint}};
  Kernel coarse, mark, units, args;
  std::vector<std::unique_ptr<Kernel>> refine;  // per run length (specialization constant SPAN)
  Kernel select;
};

Similarity::Similarity(const GpuContext& ctx) : ctx_(ctx), kernels_(std::make_unique<Kernels>(ctx)) {}
Similarity::~Similarity() = default;

void Similarity::setTemplates(Batch& batch, const std::vector<LinemodTemplate>& templates, const FeatureParams& fp,
                              const MatchParams& params, const std::vector<LinearMemoryLayout>& layouts,
                              const std::vector<match::TemplateDepthGate>& gates) {
  feature_params_ = fp;
  layouts_ = layouts;
  chunks_.clear();
  ranges_.assign(templates.size(), {});
  const std::size_t levels = layouts.size();
  // Chunks: at most 16384 templates (workgroup rows) and features that fit one binding.
  // Each chunk is some 14 dispatches, each a barrier on llvmpipe, so chunks are as large as
  // that allows; should one chunk's refinement units outgrow a binding of unit scores (a
  // frame where templates match nearly everywhere), read() says so and the matcher lays the
  // templates out again in chunks half the size (splitChunks).
  const auto& dev = ctx_.device();
  const std::size_t max_bytes = std::min<std::size_t>(dev.max_storage_buffer_range, 64u << 20);
  // A candidate takes 16 bytes (after a 16-byte count) and its result 8: many banks at once can
  // find more candidates than one binding holds, and then the matcher splits the chunks into
  // passes, so chunks are kept to 16384 templates for the split to have something to split.
  max_capacity_ = static_cast<uint32_t>(std::min<std::size_t>((dev.max_storage_buffer_range - 16) / 16, 1u << 30));
  // A first frame whose candidates overflow the list runs its coarse level again: start with
  // room for as many as real frames give (IC-BIN's cup: 15 a template; LM-O's clutter: 70),
  // 1 KB a template at most.
  capacity_ = static_cast<uint32_t>(std::min<std::size_t>(
      std::max<std::size_t>(capacity_, kFirstCandidatesPerTemplate * templates.size()), max_capacity_));
  const std::size_t max_templates = chunk_templates_;
  std::size_t units_per_template = 0, binding_units = 0;
  if (levels > 1) {
    const auto& fl = layouts[0];
    units_per_template = static_cast<std::size_t>((fl.rows + kUnitBand - 1) / kUnitBand) *
                         static_cast<std::size_t>(fl.stride / match::kRefineWindow);
    binding_units =
        std::min<std::size_t>({dev.max_storage_buffer_range, dev.max_texel_buffer_elements * 16, 1u << 30}) /
        kUnitScoreBytes;
    // Tests lower it to reach the chunk split with a small bank.
    if (const char* env = std::getenv("VKPOSE_MAX_REFINE_UNITS"); env && std::atoll(env) > 0)
      binding_units = std::min<std::size_t>(binding_units, static_cast<std::size_t>(std::atoll(env)));
  }
  std::size_t t = 0;
  std::size_t largest = 0;
  while (t < templates.size()) {
    Chunk chunk;
    chunk.first_template = static_cast<int>(t);
    std::vector<int32_t> headers[2], offsets[2];
    while (t < templates.size() && static_cast<std::size_t>(chunk.template_count) < max_templates) {
      std::size_t add = 0;
      for (const auto& level : templates[t].levels) add += level.features.size() * 4;
      if (chunk.template_count > 0 && (offsets[0].size() + offsets[1].size()) * 4 + add > max_bytes) break;
      const match::CoarseRange range =
          appendTemplate(templates[t], layouts, params, gates.empty() ? match::TemplateDepthGate{} : gates[t], headers,
                         offsets);
      ranges_[t] = range;
      chunk.coarse_invocations = std::max<std::size_t>(
          chunk.coarse_invocations, static_cast<std::size_t>((range.rows + kCoarseRows - 1) / kCoarseRows) *
                                        static_cast<std::size_t>((range.columns + 16 * kCoarseSpan - 1) /
                                                                 (16 * kCoarseSpan)));
      ++chunk.template_count;
      ++t;
    }
    largest = std::max<std::size_t>(largest, static_cast<std::size_t>(chunk.template_count));
    for (std::size_t l = 0; l < levels; ++l) {
      chunk.headers[l] = Buffer(ctx_, headers[l].size() * 4);
      chunk.offsets[l] = Buffer(ctx_, offsets[l].size() * 4);
      batch.upload(chunk.headers[l], headers[l].data(), headers[l].size() * 4);
      batch.upload(chunk.offsets[l], offsets[l].data(), offsets[l].size() * 4);
    }
    chunks_.push_back(std::move(chunk));
  }
  if (levels > 1) {
    const UnitGrid grid = unitGrid(layouts[levels - 1], layouts[0]);
    template_bands_ = largest * static_cast<std::size_t>(grid.bands);
    block_words_ = template_bands_ * static_cast<std::size_t>(grid.words_per_band);
    column_words_ = template_bands_ * static_cast<std::size_t>(grid.column_words);
    max_unit_capacity_ = static_cast<uint32_t>(std::min(largest * units_per_template, binding_units));
    unit_capacity_ = std::min(unit_capacity_, max_unit_capacity_);
  }
}

void Similarity::setDepth(Batch& batch, const match::AnchorDepthCells& cells, const std::vector<match::BandBox>& boxes) {
  depth_cells_x_ = depth_cells_y_ = 0;
  if (cells.empty()) {
    depth_.reserve(ctx_, 16);  // bound all the same
    return;
  }
  // The planes, then each band's box (r0, r1, c0, c1) as int bits.
  std::vector<uint32_t> words(cells.planes);
  for (const auto& b : boxes)
    for (const int v : {b.r0, b.r1, b.c0, b.c1}) words.push_back(static_cast<uint32_t>(v));
  const std::size_t bytes = words.size() * 4;
  depth_.reserve(ctx_, bytes);
  batch.upload(depth_, words.data(), bytes);
  depth_cells_x_ = cells.cells_x;
  depth_cells_y_ = cells.cells_y;
  depth_boxes_at_ = static_cast<int>(cells.planes.size());
}

void Similarity::record(Batch& batch, const FrameFeatures& features, std::size_t begin, std::size_t end) {
  const std::size_t coarse = layouts_.size() - 1;
  const auto& cl = layouts_[coarse];
  const bool refine = coarse > 0;
  candidates_.reserve(ctx_, 16 + static_cast<std::size_t>(capacity_) * 16, MemoryKind::HostVisible);
  // The refined matches are a subset of the candidates: as many slots never overflow.
  if (refine) refined_.reserve(ctx_, 16 + static_cast<std::size_t>(capacity_) * 16, MemoryKind::HostVisible);
  state_.reserve(ctx_, kStateBytes, MemoryKind::HostVisible);
  batch.fill(candidates_, 0u, 16);
  batch.fill(state_, 0u, kStateBytes);
  if (refine) batch.fill(refined_, 0u, 16);
  UnitGrid grid{};  // all 0 without refinement
  if (refine) {
    grid = unitGrid(cl, layouts_[0]);
    columns_.reserve(ctx_, column_words_ * 4);
    blocks_.reserve(ctx_, block_words_ * 4);
    bases_.reserve(ctx_, block_words_ * 4);
    shifts_.reserve(ctx_, template_bands_ * 4);
    occupied_.reserve(ctx_, (template_bands_ + 31) / 32 * 4);
    runs_.reserve(ctx_, runListEntries(unit_capacity_) * 16);
    scores_.reserve(ctx_, static_cast<std::size_t>(unit_capacity_) * kUnitScoreBytes);
  }
  const auto& fl = layouts_[0];
  for (std::size_t c = begin; c < std::min(end, chunks_.size()); ++c) {
    const Chunk& chunk = chunks_[c];
    const std::size_t bands = static_cast<std::size_t>(chunk.template_count) * static_cast<std::size_t>(grid.bands);
    const CoarsePush push{chunk.first_template, cl.stride, capacity_, depth_cells_x_, depth_cells_y_, depth_boxes_at_};
    if (chunk.coarse_invocations > 0)
      batch.dispatch(kernels_->coarse,
                     {features.memory(coarse), chunk.headers[coarse], chunk.offsets[coarse], candidates_, depth_}, push,
                     groupsFor(chunk.coarse_invocations, kCoarseWorkgroupSize), static_cast<uint32_t>(chunk.template_count));
    if (!refine) continue;
    const ChunkPush chunk_push{chunk.first_template, grid};
    batch.dispatch(kernels_->args, {candidates_, state_}, ArgsPush{0, unit_capacity_, capacity_}, 1);
    batch.fill(columns_, 0u, bands * static_cast<std::size_t>(grid.column_words) * 4);
    batch.fill(occupied_, 0u, (bands + 31) / 32 * 4);
    batch.dispatchIndirect(kernels_->mark, {candidates_, state_, columns_, occupied_}, chunk_push, state_,
                           kCandidateArgs);
    batch.fill(state_, 0u, 4);                          // this chunk's unit count
    batch.fill(state_, 0u, 4 * kMaxSpan, kRunCounts);  // and run counts
    const auto g = groups2DFor(bands, kWorkgroupSize);
    batch.dispatch(kernels_->units, {columns_, blocks_, bases_, shifts_, runs_, state_, occupied_},
                   UnitsPush{static_cast<uint32_t>(bands), unit_capacity_, grid}, g.x, g.y);
    batch.dispatch(kernels_->args, {candidates_, state_}, ArgsPush{1, unit_capacity_, capacity_}, 1);
    for (uint32_t span = 1; span <= kMaxSpan; ++span)
      batch.dispatchIndirect(*kernels_->refine[span - 1],
                             {features.memory(0), chunk.headers[0], chunk.offsets[0], runs_, state_, scores_},
                             RefinePush{fl.stride, unit_capacity_, grid}, state_, kRunArgs + 16 * (span - 1));
    batch.dispatchIndirect(kernels_->select,
                           {blocks_, bases_, scores_, candidates_, state_, refined_, shifts_, chunk.headers[0]},
                           SelectPush{chunk.first_template, grid, capacity_}, state_, kCandidateArgs);
  }
}

bool Similarity::splitChunks() {
  int largest = 0;
  for (const auto& c : chunks_) largest = std::max(largest, c.template_count);
  if (largest <= 1) return false;
  chunk_templates_ = static_cast<std::size_t>(largest / 2);
  return true;
}

bool Similarity::read(std::vector<match::CoarseCandidate>& candidates, std::vector<match::RefineResult>& refined) {
  const auto* words = static_cast<const uint32_t*>(candidates_.mapped());
  const uint32_t count = words[0];
  candidates.clear();
  refined.clear();
  bool complete = true;
  full_ = false;
  if (count > capacity_) {
    full_ = capacity_ == max_capacity_;
    capacity_ = static_cast<uint32_t>(
        std::min<uint64_t>(std::max<uint64_t>(count + uint64_t{count} / 4, uint64_t{capacity_} * 2), max_capacity_));
    complete = false;
  }
  units_full_ = false;
  if (layouts_.size() > 1) {
    const uint32_t max_units = static_cast<const uint32_t*>(state_.mapped())[1];
    if (max_units > unit_capacity_) {
      // A chunk's units are counted only while its candidates all fit, so the count is
      // exact: more than a binding holds means smaller chunks now, not after a pass at the
      // largest capacity.
      units_full_ = unit_capacity_ == max_unit_capacity_ || max_units > max_unit_capacity_;
      unit_capacity_ = std::min(std::max(max_units + max_units / 4, unit_capacity_ * 2), max_unit_capacity_);
      complete = false;
    }
  }
  if (!complete) return false;
  coarse_count_ = count;
  if (layouts_.size() == 1) {
    candidates.resize(count);
    for (uint32_t i = 0; i < count; ++i) {
      const uint32_t* item = words + 4 + 4 * i;
      candidates[i] = {static_cast<int>(item[0]), static_cast<int32_t>(item[1]), static_cast<int32_t>(item[2]),
                       static_cast<int>(item[3])};
    }
    return true;
  }
  // With refinement, only the candidates whose refinement passed (refine_select.comp).
  const auto* listed = static_cast<const uint32_t*>(refined_.mapped());
  const uint32_t passed = std::min(listed[0], count);
  candidates.resize(passed);
  refined.resize(passed);
  for (uint32_t i = 0; i < passed; ++i) {
    const uint32_t* item = listed + 4 + 4 * i;
    candidates[i] = {static_cast<int>(item[0]), static_cast<int32_t>(item[1]), static_cast<int32_t>(item[2]), 0};
    refined[i] = {static_cast<int>(item[3] >> 16), static_cast<int>((item[3] >> 8) & 0xFF),
                  static_cast<int>(item[3] & 0xFF)};
  }
  // The device appends in no fixed order; the host sorts (finishMatches) for determinism.
  return true;
}

}  // namespace vkpose::gpu
