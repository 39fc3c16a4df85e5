#pragma once
// LSD radix sort of 64-bit keys: for the millions of keys of a frame's matches, several times
// faster than std::sort (a pass per 11 bits of key, passes over bits all keys share skipped).
#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace vkpose::util {

/// Sorts `keys` ascending; `scratch` is reused storage (resized as needed).
inline void radixSort(std::vector<std::uint64_t>& keys, std::vector<std::uint64_t>& scratch) {
  constexpr int kDigit = 11;
  constexpr std::size_t kBuckets = std::size_t(1) << kDigit;
  std::uint64_t all_or = 0, all_and = ~std::uint64_t(0);
  for (const std::uint64_t k : keys) all_or |= k, all_and &= k;
  const std::uint64_t varying = all_or ^ all_and;  // bits that differ between some keys
  scratch.resize(keys.size());
  std::array<std::size_t, kBuckets> count{};
  for (int shift = 0; shift < 64; shift += kDigit) {
    if (((varying >> shift) & (kBuckets - 1)) == 0) continue;
    count.fill(0);
    for (const std::uint64_t k : keys) ++count[(k >> shift) & (kBuckets - 1)];
    std::size_t sum = 0;
    for (auto& c : count) {
      const std::size_t n = c;
      c = sum;
      sum += n;
    }
    for (const std::uint64_t k : keys) scratch[count[(k >> shift) & (kBuckets - 1)]++] = k;
    keys.swap(scratch);
  }
}

}  // namespace vkpose::util
