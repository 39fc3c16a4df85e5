// libFuzzer target: the BOP results CSV (loadBopResults, src/eval/bop_results.cpp).
#include "fuzz/fuzz_support.hpp"

#include "vkpose/evaluation.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, std::size_t size) {
  const std::string path = vkpose::fuzz::inputFile(data, size, "results.csv");
  vkpose::fuzz::expectNoCrash([&] { vkpose::loadBopResults(path); });
  return 0;
}
