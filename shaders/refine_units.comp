#version 450
// Lays out and numbers the units of each template band that refine_mark.comp marked:
// blocks of 16 columns from the band's first marked column on (its shift), a bit for each
// block holding a marked column. Each non-zero block word gets a range of unit slots, where
// similarity_refine.comp writes each unit's scores (the order across words does not
// matter). Runs of consecutive blocks are cut into pieces of at most kMaxSpan units and
// listed by length: a piece of L units costs L + 1 texel fetches per row and feature, where
// units one by one would cost 2 L.
#include "refine_grid.glsl"
layout(local_size_x = kWorkgroupSize) in;
layout(std430, binding = 0) readonly buffer ColumnMarks { uint columns[]; };
layout(std430, binding = 1) writeonly buffer BlockMarks { uint blocks[]; };
layout(std430, binding = 2) writeonly buffer Bases { uint bases[]; };
layout(std430, binding = 3) writeonly buffer Shifts { uint shifts[]; };
layout(std430, binding = 4) writeonly buffer Runs { uvec4 runs[]; };
layout(std430, binding = 5) buffer State { REFINE_STATE };
layout(std430, binding = 6) readonly buffer Occupied { uint occupied[]; };  // a bit per template band
layout(push_constant) uniform UnitsPushBlock { UnitsPush pc; };
void main() {
  uint tb = gl_GlobalInvocationID.y * kGridColumns * kWorkgroupSize + gl_GlobalInvocationID.x;
  if (tb >= pc.bands) return;
  // Most bands hold no window: one word tells, where the column words would take several.
  if ((occupied[tb >> 5] & (1u << (tb & 31u))) == 0u) return;
  uint first_word = tb * uint(pc.grid.column_words);
  int first = -1;
  for (int w = pc.grid.column_words - 1; w >= 0; --w) {
    uint m = columns[first_word + uint(w)];
    first = m != 0u ? w * 32 + findLSB(m) : first;
  }
  if (first < 0) return;
  uint shift = uint(first) & 15u;
  shifts[tb] = shift;
  // Column words shifted right by `shift`: each 32 bits are two blocks.
  uint next = columns[first_word];
  for (int j = 0; j < pc.grid.words_per_band; ++j) {
    uint m = 0u;
    for (int w = 16 * j; w < min(16 * j + 16, pc.grid.column_words); ++w) {
      uint current = next;
      next = w + 1 < pc.grid.column_words ? columns[first_word + uint(w + 1)] : 0u;
      uint v = shift == 0u ? current : (current >> shift) | (next << (32u - shift));
      m |= ((v & 0xFFFFu) != 0u ? 1u : 0u) << uint(2 * (w - 16 * j));
      m |= ((v >> 16u) != 0u ? 1u : 0u) << uint(2 * (w - 16 * j) + 1);
    }
    uint word = tb * uint(pc.grid.words_per_band) + uint(j);
    blocks[word] = m;
    uint slot = atomicAdd(unit_count, uint(bitCount(m)));
    bases[word] = slot;
    while (m != 0u) {
      int b = findLSB(m);
      uint rest = m >> uint(b);
      int len = rest == 0xFFFFFFFFu ? 32 - b : findLSB(~rest);
      m &= len == 32 ? 0u : ~(((1u << uint(len)) - 1u) << uint(b));
      for (int p = 0; p < len; p += kMaxSpan) {
        int span = min(kMaxSpan, len - p);
        uint k = atomicAdd(run_count[span - 1], 1u);
        if (k < runCapacity(pc.capacity, span))
          runs[runRegion(pc.capacity, span) + k] =
              uvec4(tb, shift + uint(16 * (32 * j + b + p)), slot + uint(p), 0u);
      }
      slot += uint(len);
    }
  }
}
