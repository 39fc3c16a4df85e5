// Scores of 16 consecutive positions in packed 16-bit lanes, as the similarity kernels leave them:
// `lo` holds positions 4j and 4j+2, `hi` 4j+1 and 4j+3.
uint scoreAt(uvec4 lo, uvec4 hi, int p) {
  uint v = (p & 1) == 0 ? lo[p >> 2] : hi[p >> 2];
  return (v >> (16u * uint((p & 3) >> 1))) & 0xFFFFu;
}

// Per lane, the larger of the two packed 16-bit scores.
uvec4 halvesMax(uvec4 x) { return max(x & 0xFFFFu, x >> 16u); }

// Highest of the 16 scores in `lo` and `hi`.
uint maxOfSixteen(uvec4 lo, uvec4 hi) {
  uvec4 m = max(halvesMax(lo), halvesMax(hi));
  return max(max(m.x, m.y), max(m.z, m.w));
}
