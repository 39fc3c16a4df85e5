// libFuzzer target: BOP scene_gt_info.json (loadSceneGtInfo, src/eval/dataset.cpp).
#include "fuzz/fuzz_support.hpp"

#include "vkpose/evaluation.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, std::size_t size) {
  const std::string path = vkpose::fuzz::inputFile(data, size, "scene_gt_info.json");
  vkpose::fuzz::expectNoCrash([&] { vkpose::loadSceneGtInfo(path); });
  return 0;
}
