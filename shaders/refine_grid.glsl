// Refinement works on units: one template's responses at kUnitBand consecutive finer-level rows
// (padded rows kUnitBand k .. kUnitBand k + kUnitBand - 1) and one block of 16 cells of those rows.
// Candidates of a template near each other have heavily overlapping 16 x 16 windows; each
// unit they cover is scored once, and each feature's offset is read once for the kUnitBand rows.
// The windows mark the padded columns they cover, per template and band (refine_mark.comp);
// refine_units.comp then lays that band's blocks from its first marked column on (padded
// columns shift + 16 k .. shift + 16 k + 15), so that a lone window is one block, not the
// two that blocks fixed at multiples of 16 would cut it into. A chunk's units are bits of
// a block mark array: per template, per band, `words_per_band` words of one bit per block
// (UnitGrid, kUnitBand and kMaxSpan: src/gpu/kernel_interface.h).
#include "gpu/kernel_interface.h"

int floorDiv(int a, int b) { return a >= 0 ? a / b : -((-a + b - 1) / b); }

// Finer-level cell (row, column) of the refinement window of coarse cell (r, c), as in
// match::refineWindowStart.
ivec2 windowStart(UnitGrid g, int r, int c) {
  int offset = g.T_coarse / 2 + (g.T_coarse % 2 - 1);
  return ivec2(floorDiv(2 * (r * g.T_coarse + offset) + 1, g.T_fine),
               floorDiv(2 * (c * g.T_coarse + offset) + 1, g.T_fine)) - 8;
}

// Bit of block k of band `band` of the chunk's template t.
uint blockBit(UnitGrid g, int t, int band, int k) { return uint((t * g.bands + band) * g.words_per_band * 32 + k); }

int bandOf(UnitGrid g, int row) { return (row + g.pad) / kUnitBand; }

// Runs of neighbouring units are scored together, up to kMaxSpan units (refine_units.comp).
// Each length has its own list in the runs buffer: a run of `span` units takes `span` of
// the `capacity` unit slots, so that list needs at most capacity / span entries.
uint runCapacity(uint capacity, int span) { return capacity / uint(span); }
uint runRegion(uint capacity, int span) {
  uint region = 0u;
  for (int s = 1; s < span; ++s) region += runCapacity(capacity, s);
  return region;
}

// The state buffer of a chunk's refinement (refine_args.comp writes the dispatch sizes).
#define REFINE_STATE                                                                      \
  uint unit_count;       /* this chunk's units (reset before each chunk) */               \
  uint max_units;        /* most units of any chunk: more than the capacity: run again */ \
  uint next_candidate;   /* first candidate of the next chunk */                          \
  uint first_candidate;  /* first candidate of this chunk */                              \
  uvec4 candidate_groups;          /* byte 16 */                                          \
  uvec4 run_groups[kMaxSpan];      /* byte 32: per run length */                          \
  uint run_count[kMaxSpan];        /* byte 32 + 16 kMaxSpan */
