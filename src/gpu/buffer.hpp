#pragma once
// A Vulkan storage buffer. Device-local buffers are filled and read through staging copies
// recorded in a gpu::Batch; host-visible buffers are mapped.
#include <cstddef>
#include <cstdint>

#include "gpu/vulkan.hpp"

namespace vkpose::gpu {

enum class MemoryKind { DeviceLocal, HostVisible };

class Buffer {
 public:
  Buffer() = default;
  Buffer(const GpuContext& ctx, std::size_t bytes, MemoryKind kind = MemoryKind::DeviceLocal);
  ~Buffer();
  Buffer(Buffer&& other) noexcept;
  Buffer& operator=(Buffer&& other) noexcept;
  Buffer(const Buffer&) = delete;
  Buffer& operator=(const Buffer&) = delete;

  vk::Buffer handle() const { return buffer_; }
  std::size_t size() const { return bytes_; }
  bool empty() const { return bytes_ == 0; }
  /// Host pointer of a HostVisible buffer (nullptr for DeviceLocal).
  void* mapped() const { return mapped_; }

  /// Makes sure the buffer holds at least `bytes`; reallocates (losing contents) if not.
  /// InputError when the context's buffers would exceed its memory limit or the allocation
  /// fails (too many or too large template banks).
  void reserve(const GpuContext& ctx, std::size_t bytes, MemoryKind kind = MemoryKind::DeviceLocal);

 private:
  void release();
  vk::Device device_;
  vk::Buffer buffer_;
  vk::DeviceMemory memory_;
  std::size_t bytes_ = 0;
  /// The memory allocation's size: counted in bufferMemory() and in the context's budget.
  std::size_t allocated_ = 0;
  void* mapped_ = nullptr;
  ContextState* state_ = nullptr;  ///< whose allocated_bytes this buffer counts in
};

/// Bytes held by live Buffer objects (staging buffers included), and the most held at once
/// since the process started or the last resetBufferPeak(): a benchmark's GPU memory figure.
struct BufferMemory {
  std::size_t live = 0, peak = 0;
};
BufferMemory bufferMemory();
/// Starts a new peak from what is live now.
void resetBufferPeak();

/// A range of a buffer bound to one shader binding. Ranges must stay within the device's
/// maxStorageBufferRange (128 MiB on lavapipe): callers chunk larger data.
struct BufferView {
  const Buffer* buffer = nullptr;
  std::size_t offset = 0;
  std::size_t range = 0;  ///< 0: to the end of the buffer
  BufferView(const Buffer& b) : buffer(&b) {}  // NOLINT: implicit on purpose
  BufferView(const Buffer& b, std::size_t off, std::size_t len) : buffer(&b), offset(off), range(len) {}
};

}  // namespace vkpose::gpu
