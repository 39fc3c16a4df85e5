// Which Vulkan memory type a buffer takes (gpu::chooseMemoryType): mapped buffers, which the
// host reads back (staging, match candidates), prefer host-cached memory where a device has it.
#include <initializer_list>

#include <gtest/gtest.h>

#include "gpu/vulkan.hpp"
#include "vkpose/error.hpp"

namespace vkpose {
namespace {

using F = vk::MemoryPropertyFlagBits;

vk::PhysicalDeviceMemoryProperties memoryTypes(std::initializer_list<vk::MemoryPropertyFlags> types) {
  vk::PhysicalDeviceMemoryProperties memory{};
  for (const auto& flags : types) memory.memoryTypes[memory.memoryTypeCount++].propertyFlags = flags;
  return memory;
}

TEST(MemoryType, MappedBuffersTakeHostCachedMemoryWhereThereIsSome) {
  // A discrete NVIDIA GPU's list: device memory; system memory write-combined; system memory
  // cached; device memory through the PCIe BAR.
  const auto nvidia = memoryTypes({F::eDeviceLocal, F::eHostVisible | F::eHostCoherent,
                                   F::eHostVisible | F::eHostCoherent | F::eHostCached,
                                   F::eDeviceLocal | F::eHostVisible | F::eHostCoherent});
  EXPECT_EQ(gpu::chooseMemoryType(nvidia, 0xF, false, "nvidia"), 0u);
  EXPECT_EQ(gpu::chooseMemoryType(nvidia, 0xF, true, "nvidia"), 2u);
  // A buffer that may not take the cached type falls back to the plain mapped one ...
  EXPECT_EQ(gpu::chooseMemoryType(nvidia, 0xB, true, "nvidia"), 1u);
  // ... or to the BAR, the only mapped type it may take.
  EXPECT_EQ(gpu::chooseMemoryType(nvidia, 0x9, true, "nvidia"), 3u);
  // Device-local buffers take the first device-local type they may.
  EXPECT_EQ(gpu::chooseMemoryType(nvidia, 0x8, false, "nvidia"), 3u);
  // lavapipe: one type, everything at once.
  const auto lavapipe =
      memoryTypes({F::eDeviceLocal | F::eHostVisible | F::eHostCoherent | F::eHostCached});
  EXPECT_EQ(gpu::chooseMemoryType(lavapipe, 0x1, true, "llvmpipe"), 0u);
  EXPECT_EQ(gpu::chooseMemoryType(lavapipe, 0x1, false, "llvmpipe"), 0u);
  // Nothing mapped: a DeviceError naming the device.
  try {
    gpu::chooseMemoryType(nvidia, 0x1, true, "nvidia");
    FAIL() << "no mapped type, yet one was chosen";
  } catch (const DeviceError& e) {
    EXPECT_NE(std::string(e.what()).find("mapped buffers on nvidia"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace vkpose
