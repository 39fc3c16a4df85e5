// Sum of one template's feature responses at 16 consecutive cell positions of one row.
// Each feature is a byte offset into the linear memories (position (0, 0) of its grid
// plane); 16 responses are 4 words read at that offset plus the row's base, shifted into
// alignment. Up to 63 features add up in packed bytes (63 * 4 < 256), then widen into
// packed 16-bit lanes: `lo` holds positions 4j and 4j+2, `hi` 4j+1 and 4j+3.
layout(std430, binding = 0) readonly buffer Memory { uint memory[]; };
layout(std430, binding = 2) readonly buffer Features { int feature_offsets[]; };

void scoreSixteen(int first, int count, int base, out uvec4 lo, out uvec4 hi) {
  lo = uvec4(0u);
  hi = uvec4(0u);
  int f = first;
  int end = first + count;
  while (f < end) {
    int chunk_end = min(f + 63, end);
    uvec4 acc = uvec4(0u);
    for (; f < chunk_end; ++f) {
      uint off = uint(feature_offsets[f] + base);
      uint w = off >> 2;
      uint s = (off & 3u) * 8u;
      uvec4 a = uvec4(memory[w], memory[w + 1u], memory[w + 2u], memory[w + 3u]);
      if (s != 0u) a = (a >> s) | (uvec4(a.yzw, memory[w + 4u]) << (32u - s));
      acc += a;
    }
    lo += acc & 0x00FF00FFu;
    hi += (acc >> 8u) & 0x00FF00FFu;
  }
}

uint scoreAt(uvec4 lo, uvec4 hi, int p) {
  uint v = (p & 1) == 0 ? lo[p >> 2] : hi[p >> 2];
  return (v >> (16u * uint((p & 3) >> 1))) & 0xFFFFu;
}

// Template header: first feature, feature count, first cell column, first cell row, raw
// threshold, unused.
layout(std430, binding = 1) readonly buffer Templates { int headers[]; };
const int HEADER_INTS = 6;
