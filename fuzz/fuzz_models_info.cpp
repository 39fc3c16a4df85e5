// libFuzzer target: BOP models_info.json (loadModelsInfo, src/eval/dataset.cpp).
#include "fuzz/fuzz_support.hpp"

#include "vkpose/evaluation.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, std::size_t size) {
  const std::string path = vkpose::fuzz::inputFile(data, size, "models_info.json");
  vkpose::fuzz::expectNoCrash([&] { vkpose::loadModelsInfo(path); });
  return 0;
}
