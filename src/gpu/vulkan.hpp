#pragma once
// Private Vulkan-Hpp state behind vkpose::GpuContext. Only src/gpu and the GPU stage files
// include this; public headers stay free of Vulkan types.
#include <vulkan/vulkan.hpp>

#include <atomic>
#include <string>

#include "vkpose/device.hpp"

namespace vkpose::gpu {

struct ContextState {
  vk::Instance instance;
  vk::DebugUtilsMessengerEXT messenger;
  vk::PhysicalDevice physical;
  vk::Device device;
  vk::Queue queue;
  uint32_t queue_family = 0;
  /// Nanoseconds per timestamp tick, and the mask of valid timestamp bits on the queue (0:
  /// the queue writes no timestamps).
  double timestamp_period_ns = 0;
  uint64_t timestamp_mask = 0;
  vk::CommandPool command_pool;
  vk::PhysicalDeviceMemoryProperties memory;
  GpuDeviceInfo info;
  std::atomic<uint32_t> validation_errors{0};
  /// Device time of every submit waited for so far, nanoseconds (from timestamps at each
  /// command buffer's start and end; stays 0 where the queue writes none).
  std::atomic<uint64_t> device_ns{0};
  /// Bytes of the buffers of this context alive now, and the most they may add up to: the
  /// largest device-local heap, or VKPOSE_GPU_MEMORY_LIMIT_MIB when set (tests lower it).
  std::atomic<uint64_t> allocated_bytes{0};
  uint64_t memory_limit = 0;
  PFN_vkCreateDebugUtilsMessengerEXT create_messenger = nullptr;
  PFN_vkDestroyDebugUtilsMessengerEXT destroy_messenger = nullptr;
};

/// The memory type a buffer of `host_visible` memory (mapped: staging, match candidates) or
/// device-local memory takes among those `type_bits` allows: device-local memory the first
/// device-local type; mapped memory host-visible and coherent, host-cached where a type is,
/// because the host reads it back. A discrete GPU's first mapped type is write-combined
/// (NVIDIA) or the device's own memory seen through the PCIe BAR: written fast, read by the
/// CPU at a fraction of memory speed. Throws DeviceError when no type fits.
uint32_t chooseMemoryType(const vk::PhysicalDeviceMemoryProperties& memory, uint32_t type_bits, bool host_visible,
                          const std::string& device_name);

}  // namespace vkpose::gpu
