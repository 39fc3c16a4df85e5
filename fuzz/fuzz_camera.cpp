// libFuzzer target: camera JSON (loadCamera, src/io/camera_io.cpp): camera.json or a scene_camera.json entry.
#include "fuzz/fuzz_support.hpp"

#include "vkpose/geometry.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, std::size_t size) {
  const std::string path = vkpose::fuzz::inputFile(data, size, "camera.json");
  vkpose::fuzz::expectNoCrash([&] { vkpose::loadCamera(path); });
  vkpose::fuzz::expectNoCrash([&] { vkpose::loadCamera(path, "3"); });
  return 0;
}
