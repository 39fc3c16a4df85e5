// Vulkan validation: errors the Khronos layer reports are counted, per context and for the
// whole process; the test support fails the test during which the count grows.
#include <cstdlib>

#include <gtest/gtest.h>

#include "gpu/vulkan.hpp"
#include "vkpose/device.hpp"
#include "vkpose/error.hpp"

namespace vkpose {
namespace {

TEST(VulkanValidation, AnInvalidCallIsCountedOnceInTheContextAndTheProcess) {
  // In a child process: the error would otherwise fail this test through the listener.
  EXPECT_EXIT(
      {
        GpuOptions options;
        options.validation = true;
        int code = 0;
        try {
          GpuContext ctx(options);
          const uint32_t before = GpuContext::processValidationErrors();
          VkBufferCreateInfo info{};
          info.sType = VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO;
          info.size = 0;  // VUID-VkBufferCreateInfo-size-00912: size must be greater than 0
          info.usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT;
          VkBuffer buffer = VK_NULL_HANDLE;
          VkDevice device = ctx.state().device;
          if (vkCreateBuffer(device, &info, nullptr, &buffer) == VK_SUCCESS) vkDestroyBuffer(device, buffer, nullptr);
          code = ctx.validationErrors() == 1 && GpuContext::processValidationErrors() - before == 1 ? 0 : 1;
        } catch (const DeviceError&) {
          code = 2;  // the layer is not installed
        }
        std::_Exit(code);
      },
      ::testing::ExitedWithCode(0), "");
}

}  // namespace
}  // namespace vkpose
