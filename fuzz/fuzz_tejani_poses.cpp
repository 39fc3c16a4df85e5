// libFuzzer target: Tejani et al. pose files (loadTejaniPoses, src/eval/tejani_poses.cpp).
#include "fuzz/fuzz_support.hpp"

#include "vkpose/evaluation.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, std::size_t size) {
  const std::string path = vkpose::fuzz::inputFile(data, size, "poses.txt");
  vkpose::fuzz::expectNoCrash([&] { vkpose::loadTejaniPoses(path); });
  return 0;
}
