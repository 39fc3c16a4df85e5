// libFuzzer target: the template bank reader (loadBank, src/io/bank_io.cpp).
#include "fuzz/fuzz_support.hpp"
#include "vkpose/template_bank.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, std::size_t size) {
  const std::string path = vkpose::fuzz::inputFile(data, size, "bank.vkpb");
  vkpose::fuzz::expectNoCrash([&] { vkpose::loadBank(path); });
  return 0;
}
