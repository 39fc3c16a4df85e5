#include "gpu/buffer.hpp"

#include <atomic>
#include <utility>

namespace vkpose::gpu {

namespace {
std::atomic<std::size_t> live_bytes{0}, peak_bytes{0};

void countAllocation(std::size_t bytes) {
  const std::size_t now = live_bytes.fetch_add(bytes) + bytes;
  for (std::size_t peak = peak_bytes.load(); now > peak && !peak_bytes.compare_exchange_weak(peak, now);) {
  }
}
}  // namespace

BufferMemory bufferMemory() { return {live_bytes.load(), peak_bytes.load()}; }

void resetBufferPeak() { peak_bytes = live_bytes.load(); }

Buffer::Buffer(const GpuContext& ctx, std::size_t bytes, MemoryKind kind) { reserve(ctx, bytes, kind); }

Buffer::~Buffer() { release(); }

Buffer::Buffer(Buffer&& o) noexcept { *this = std::move(o); }

Buffer& Buffer::operator=(Buffer&& o) noexcept {
  if (this != &o) {
    release();
    device_ = std::exchange(o.device_, {});
    buffer_ = std::exchange(o.buffer_, {});
    memory_ = std::exchange(o.memory_, {});
    bytes_ = std::exchange(o.bytes_, 0);
    mapped_ = std::exchange(o.mapped_, nullptr);
    allocated_ = std::exchange(o.allocated_, 0);
  }
  return *this;
}

void Buffer::release() {
  if (!device_) return;
  if (mapped_) device_.unmapMemory(memory_);
  device_.destroyBuffer(buffer_);
  device_.freeMemory(memory_);
  live_bytes -= allocated_;
  allocated_ = 0;
  device_ = vk::Device{};
  buffer_ = vk::Buffer{};
  memory_ = vk::DeviceMemory{};
  bytes_ = 0;
  mapped_ = nullptr;
}

void Buffer::reserve(const GpuContext& ctx, std::size_t bytes, MemoryKind kind) {
  const bool host = kind == MemoryKind::HostVisible;
  if (bytes <= bytes_ && (mapped_ != nullptr) == host) return;
  release();
  auto& s = ctx.state();
  // Vulkan forbids zero-sized buffers; a 4-byte buffer stands in for an empty one.
  const std::size_t alloc = std::max<std::size_t>(bytes, 4);
  device_ = s.device;
  buffer_ = s.device.createBuffer(
      {.size = alloc,
       .usage = vk::BufferUsageFlagBits::eStorageBuffer | vk::BufferUsageFlagBits::eUniformTexelBuffer |
                vk::BufferUsageFlagBits::eTransferSrc |
                vk::BufferUsageFlagBits::eTransferDst | vk::BufferUsageFlagBits::eIndirectBuffer});
  auto req = s.device.getBufferMemoryRequirements(buffer_);
  const auto flags = host ? vk::MemoryPropertyFlagBits::eHostVisible | vk::MemoryPropertyFlagBits::eHostCoherent
                          : vk::MemoryPropertyFlags(vk::MemoryPropertyFlagBits::eDeviceLocal);
  memory_ = s.device.allocateMemory({.allocationSize = req.size,
                                     .memoryTypeIndex = s.memoryType(req.memoryTypeBits, flags)});
  s.device.bindBufferMemory(buffer_, memory_, 0);
  allocated_ = req.size;
  countAllocation(allocated_);
  if (host) mapped_ = s.device.mapMemory(memory_, 0, VK_WHOLE_SIZE);
  bytes_ = bytes;
}

}  // namespace vkpose::gpu
