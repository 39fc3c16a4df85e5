#include "gpu/buffer.hpp"

#include <atomic>
#include <string>
#include <utility>

#include <fmt/format.h>

#include "vkpose/error.hpp"

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
    state_ = std::exchange(o.state_, nullptr);
    allocated_ = std::exchange(o.allocated_, 0);
  }
  return *this;
}

namespace {
std::string mib(uint64_t bytes) { return fmt::format("{:.1f} MiB", static_cast<double>(bytes) / (1 << 20)); }

InputError outOfMemory(const ContextState& s, uint64_t bytes, const char* why) {
  return InputError(fmt::format("not enough GPU memory on {}: {} more with {} in use {}; use fewer or smaller "
                                "template banks, or a smaller image",
                                s.info.name, mib(bytes), mib(s.allocated_bytes.load()), why));
}
}  // namespace

void Buffer::release() {
  if (!device_) return;
  if (mapped_) device_.unmapMemory(memory_);
  device_.destroyBuffer(buffer_);
  device_.freeMemory(memory_);
  if (state_) state_->allocated_bytes -= allocated_;
  state_ = nullptr;
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
  // The budget is checked before Vulkan is asked: a driver may over-commit (lavapipe takes
  // host memory until the machine swaps) instead of failing the allocation.
  if (s.memory_limit && s.allocated_bytes.load() + alloc > s.memory_limit)
    throw outOfMemory(s, alloc, fmt::format("would exceed the device's {}", mib(s.memory_limit)).c_str());
  vk::Buffer buffer = s.device.createBuffer(
      {.size = alloc,
       .usage = vk::BufferUsageFlagBits::eStorageBuffer | vk::BufferUsageFlagBits::eUniformTexelBuffer |
                vk::BufferUsageFlagBits::eTransferSrc |
                vk::BufferUsageFlagBits::eTransferDst | vk::BufferUsageFlagBits::eIndirectBuffer});
  auto req = s.device.getBufferMemoryRequirements(buffer);
  vk::DeviceMemory memory;
  try {
    memory = s.device.allocateMemory({.allocationSize = req.size,
                                      .memoryTypeIndex = chooseMemoryType(s.memory, req.memoryTypeBits, host, s.info.name)});
  } catch (const vk::OutOfDeviceMemoryError&) {
    s.device.destroyBuffer(buffer);
    throw outOfMemory(s, req.size, "(the allocation failed)");
  } catch (const vk::OutOfHostMemoryError&) {
    s.device.destroyBuffer(buffer);
    throw outOfMemory(s, req.size, "(the allocation failed: out of host memory)");
  }
  device_ = s.device;
  buffer_ = buffer;
  memory_ = memory;
  state_ = &s;
  allocated_ = req.size;
  s.allocated_bytes += allocated_;
  s.device.bindBufferMemory(buffer_, memory_, 0);
  countAllocation(allocated_);
  if (host) mapped_ = s.device.mapMemory(memory_, 0, VK_WHOLE_SIZE);
  bytes_ = bytes;
}

}  // namespace vkpose::gpu
