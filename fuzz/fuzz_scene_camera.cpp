// libFuzzer target: BOP scene_camera.json (loadSceneCamera, src/eval/dataset.cpp).
#include "fuzz/fuzz_support.hpp"

#include "vkpose/evaluation.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, std::size_t size) {
  const std::string path = vkpose::fuzz::inputFile(data, size, "scene_camera.json");
  vkpose::fuzz::expectNoCrash([&] { vkpose::loadSceneCamera(path, vkpose::Camera{}); });
  return 0;
}
