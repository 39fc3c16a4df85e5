// The boundary between the compute kernels (shaders/*.comp) and their C++ hosts: the constants
// both sides use and the layouts of the kernels' push constants, written once. This file is
// GLSL 450 and C++20 at the same time: kernels #include "gpu/kernel_interface.h" (glslc -I src,
// cmake/EmbedShaders.cmake), hosts the same path; a value changed here changes on both sides,
// where two copies kept equal "by comment" could drift apart.
//
// So it sticks to what both languages read alike: `const` scalars with suffixed literals
// (1e-3f is one rounding in both), and C-style structs of 4-byte scalars without initializers.
// Push constants use the std430 layout, which puts such members at consecutive 4-byte offsets
// with no padding, as C++ does; no vec3 or bool (their alignment and size differ). A kernel
// holds its struct as the one member of its push-constant block,
//   layout(push_constant) uniform SizePushBlock { SizePush pc; };
// and reads pc.width as before. Under C++ the names live in vkpose::gpu, GLSL's `uint` is
// uint32_t, and each struct's size is checked at the end.
#ifndef VKPOSE_GPU_KERNEL_INTERFACE_H
#define VKPOSE_GPU_KERNEL_INTERFACE_H

#ifdef __cplusplus
#include <cstddef>
#include <cstdint>

#include "vkpose/geometry.hpp"

namespace vkpose::gpu {
using uint = std::uint32_t;
static_assert(sizeof(int) == 4 && sizeof(float) == 4, "GLSL's int and float are 32 bits");
#else
// vkpose::FloatIntrinsics (include/vkpose/geometry.hpp) on the C++ side, a public type this
// file cannot define; the checks at the end keep the two layouts equal.
struct FloatIntrinsics {
  float fx, fy, cx, cy;
};
#endif

// ---- dispatch shapes ------------------------------------------------------------------

// Invocations per workgroup (local_size_x) of every one-dimensional kernel but the coarse
// similarity pass and refine_args; hosts round their dispatches up to it (gpu::groupsFor).
const uint kWorkgroupSize = 64u;
// Largest x extent of a 2D grid of workgroups (gpu::groups2DFor); kernels dispatched so find
// their index as (gl_GlobalInvocationID.y * kGridColumns * kWorkgroupSize + x).
const uint kGridColumns = 32768u;

// ---- feature kernels (shaders/common.glsl) ----------------------------------------------

// Sliding-window kernels take kPixelGroup neighbouring outputs of a row, or of a column, per
// invocation: neighbours share most of their inputs.
const int kPixelGroup = 4;

// gaussian_blur7_rows, gaussian_blur7_cols, orientation_vote, median5
struct SizePush {
  int width, height;
};
struct SobelPush {
  int width, height;
  float threshold_sq;   // squared gradient magnitude an orientation needs
  int write_magnitude;  // 0: skip the magnitude stores (frames need none)
};
struct PyrDownPush {
  int src_width, src_height, width, height;
};
struct DepthNormalsPush {
  int width, height;
  int distance_threshold;    // mm: farther pixels get no normal
  int difference_threshold;  // mm: neighbours differing more are left out
};
struct DownsampleLabelsPush {
  int src_width, width, height;
};
// spread_rows, spread
struct SpreadPush {
  int width, height, T;
};
struct LinearizePush {
  int width, height, T, pad, stride, rows;
  int outside;  // response of cells outside the image (MatchParams::outside_response), every bin
  int modality;
};

// ---- similarity kernels (similarity_common.glsl, refine_grid.glsl) --------------------

// Ints per template header (their meaning: similarity_common.glsl).
const int kHeaderInts = 12;
// Features whose byte sums (responses 0..4) add up before they widen to 16 bits: 63 * 4 < 256.
const int kFeaturesPer8Bit = 63;
// One coarse invocation scores kCoarseRows rows of kCoarseSpan blocks of 16 positions.
const int kCoarseRows = 2;
const int kCoarseSpan = 3;
// The coarse pass's workgroup size: a template needs about 15 invocations at 640 x 480, and on
// llvmpipe each idle 8-lane vector of a workgroup still costs a pass through the shader, so
// kWorkgroupSize would spend most of the time on empty lanes.
const uint kCoarseWorkgroupSize = 16u;
// Rows of a refinement unit (refine_grid.glsl).
const int kUnitBand = 4;
// Longest run of neighbouring units one refinement invocation scores; runs of each length
// are listed apart and scored by a kernel specialized for that length.
const int kMaxSpan = 4;

// A chunk's grid of refinement units (refine_grid.glsl).
struct UnitGrid {
  int T_coarse, T_fine;
  int pad;             // finer layout's padding cells
  int bands;           // bands of the finer layout's padded rows
  int words_per_band;  // block mark words per band
  int column_words;    // column mark words per band
};
struct CoarsePush {
  int template_base;  // global id of this chunk's first template
  int stride;         // cells per linear-memory row (a multiple of 32)
  uint capacity;      // candidate slots
  int cells_x;        // anchor cells per row; 0: no depth pruning
  int cells_y;
  int boxes_at;       // the band boxes' first texel in depth_cells
};
// refine_mark
struct ChunkPush {
  int template_base;
  UnitGrid grid;
};
// refine_select
struct SelectPush {
  int template_base;
  UnitGrid grid;
  uint capacity;  // slots of the refined-match list
};
struct UnitsPush {
  uint bands;     // template bands of the chunk
  uint capacity;  // unit slots
  UnitGrid grid;
};
struct ArgsPush {
  uint stage;  // 0: after the coarse pass, 1: after the units are numbered
  uint unit_capacity, candidate_capacity;
};
struct RefinePush {
  int stride;
  uint capacity;  // unit slots
  UnitGrid grid;
};

// ---- cluster scoring (cluster_score.comp) ------------------------------------------------

struct ScorePush {
  FloatIntrinsics camera;
  int width, height;  // scene depth image
  uint member_count;
  int normal_step;    // pixels either side of a scene normal's centre
  float max_jump;     // metres: a depth step this large ends a normal
  float depth_cap;    // metres
};

// ---- template rasterizer (raster_common.glsl; CPU twin src/render/raster_math.hpp) -------

const float kSubpixel = 8.0f;       // fixed point: 1/8 pixel
const float kNearZ = 1e-3f;         // metres: a triangle with a corner this near or nearer is clipped
const float kClipZ = 2e-3f;         // metres: ... at this depth (clipFace), so no corner lies near zero
const float kGuardPx = 1048576.0f;  // screen coordinates beyond this are dropped
// RasterPush::flags
const uint kRasterVertexNormals = 1u;
const uint kRasterVertexColours = 2u;
const uint kRasterDepthOnly = 4u;  // the resolve pass writes depth alone (from pass 1's keys)

struct RasterPush {
  FloatIntrinsics camera;
  int width, height;
  uint face_count;
  uint flags;  // kRasterVertexNormals | kRasterVertexColours | kRasterDepthOnly
};

#ifdef __cplusplus
static_assert(sizeof(FloatIntrinsics) == 16 && offsetof(FloatIntrinsics, fx) == 0 && offsetof(FloatIntrinsics, fy) == 4 &&
                  offsetof(FloatIntrinsics, cx) == 8 && offsetof(FloatIntrinsics, cy) == 12,
              "the GLSL FloatIntrinsics above: four floats");
static_assert(sizeof(SizePush) == 8 && sizeof(SobelPush) == 16 && sizeof(PyrDownPush) == 16 &&
              sizeof(DepthNormalsPush) == 16 && sizeof(DownsampleLabelsPush) == 12 && sizeof(SpreadPush) == 12 &&
              sizeof(LinearizePush) == 32);
static_assert(sizeof(UnitGrid) == 24 && sizeof(CoarsePush) == 24 && sizeof(ChunkPush) == 28 && sizeof(SelectPush) == 32 &&
              sizeof(UnitsPush) == 32 && sizeof(ArgsPush) == 12 && sizeof(RefinePush) == 32);
static_assert(sizeof(ScorePush) == 40 && sizeof(RasterPush) == 32);
}  // namespace vkpose::gpu
#endif

#endif  // VKPOSE_GPU_KERNEL_INTERFACE_H
