#pragma once
// LSD radix sort of 64-bit keys: for the millions of keys of a frame's matches, several times
// faster than std::sort (a pass per 11 bits of key, passes over bits all keys share skipped).
#include <array>
#include <bit>
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

/// The order (indices) that sorts `keys` ascending, equal keys in index order. The index rides
/// below the key, so the keys' bits and the largest index's must fit 64 (fitsWithIndex()).
inline std::vector<std::uint32_t> stableOrder(const std::vector<std::uint64_t>& keys) {
  const int index_bits = static_cast<int>(std::bit_width(keys.empty() ? 0u : keys.size() - 1));
  std::vector<std::uint64_t> packed(keys.size()), scratch;
  for (std::size_t i = 0; i < keys.size(); ++i) packed[i] = index_bits > 0 ? (keys[i] << index_bits) | i : keys[i];
  radixSort(packed, scratch);
  const std::uint64_t mask = index_bits > 0 ? (std::uint64_t(1) << index_bits) - 1 : 0;
  std::vector<std::uint32_t> order(keys.size());
  for (std::size_t k = 0; k < packed.size(); ++k) order[k] = static_cast<std::uint32_t>(packed[k] & mask);
  return order;
}

/// Whether keys of `key_bits` bits leave room for the index of each of `count` keys.
inline bool fitsWithIndex(int key_bits, std::size_t count) {
  return count <= (std::size_t(1) << 32) && key_bits + static_cast<int>(std::bit_width(count == 0 ? 0u : count - 1)) <= 64;
}

}  // namespace vkpose::util
