// libFuzzer target: mesh loading through vkpose's wrapper of assimp (loadMesh,
// src/render/mesh.cpp). The first byte picks the format by the file's extension (STL, PLY,
// OBJ: what vkpose documents), the rest is the file.
#include "fuzz/fuzz_support.hpp"

#include "vkpose/geometry.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, std::size_t size) {
  if (size < 1) return 0;
  static const char* const kNames[] = {"mesh.stl", "mesh.ply", "mesh.obj"};
  const std::string path = vkpose::fuzz::inputFile(data + 1, size - 1, kNames[data[0] % 3]);
  vkpose::fuzz::expectNoCrash([&] { vkpose::loadMesh(path, vkpose::MeshUnits::Auto); });
  return 0;
}
