// libFuzzer target: the template bank reader (loadBank, src/training/bank_io.cpp). Each input is
// read twice: as it is, and with its header's payload size and its checksum made to fit, so
// that mutations reach the payload parser instead of stopping at the checksum.
#include <cstring>
#include <vector>

#include "fuzz/fuzz_support.hpp"
#include "vkpose/bank.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, std::size_t size) {
  const std::string path = vkpose::fuzz::inputFile(data, size, "bank.vkpb");
  vkpose::fuzz::expectNoCrash([&] { vkpose::loadBank(path); });
  constexpr std::size_t kHeader = 24, kChecksum = 8;
  if (size < kHeader + kChecksum) return 0;
  std::vector<uint8_t> fixed(data, data + size);
  const uint64_t payload = size - kHeader - kChecksum;
  std::memcpy(fixed.data() + 16, &payload, 8);
  const uint64_t sum = vkpose::fnv1a64(fixed.data(), size - kChecksum);
  std::memcpy(fixed.data() + size - kChecksum, &sum, 8);
  const std::string fixed_path = vkpose::fuzz::inputFile(fixed.data(), fixed.size(), "bank_fixed.vkpb");
  vkpose::fuzz::expectNoCrash([&] { vkpose::loadBank(fixed_path); });
  return 0;
}
