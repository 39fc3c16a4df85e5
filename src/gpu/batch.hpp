#pragma once
// Records everything a frame needs (uploads, dispatches, downloads) into one command buffer,
// submitted once with one fence. A barrier follows each recorded operation, so each dispatch
// sees the results of everything recorded before it.
#include <algorithm>
#include <cstddef>
#include <initializer_list>
#include <map>
#include <string>
#include <vector>

#include "gpu/buffer.hpp"
#include "gpu/kernel.hpp"
#include "gpu/kernel_interface.h"

namespace vkpose::gpu {

class Batch {
 public:
  explicit Batch(const GpuContext& ctx);
  ~Batch();
  Batch(const Batch&) = delete;
  Batch& operator=(const Batch&) = delete;

  /// Copies `bytes` from host memory (copied now, so `data` may go away) into `dst` at `offset`.
  void upload(const Buffer& dst, const void* data, std::size_t bytes, std::size_t offset = 0);
  /// Like upload(), but returns the staging memory for the caller to fill (before submit()):
  /// data that needs converting anyway is written there once instead of copied twice.
  void* uploadInPlace(const Buffer& dst, std::size_t bytes, std::size_t offset = 0);
  /// Fills `bytes` of `dst` at `offset` with the 32-bit word `value`.
  void fill(const Buffer& dst, uint32_t value, std::size_t bytes = VK_WHOLE_SIZE, std::size_t offset = 0);
  /// Records a dispatch of `groups` workgroups with the given buffers and push constants.
  void dispatchRaw(const Kernel& kernel, std::initializer_list<BufferView> buffers, const void* push,
                   std::size_t push_bytes, uint32_t groups_x, uint32_t groups_y = 1, uint32_t groups_z = 1);
  template <class Push>
  void dispatch(const Kernel& kernel, std::initializer_list<BufferView> buffers, const Push& push,
                uint32_t gx, uint32_t gy = 1, uint32_t gz = 1) {
    dispatchRaw(kernel, buffers, &push, sizeof(Push), gx, gy, gz);
  }
  /// `groups` workgroups of a one-dimensional kernel that indexes with LINEAR_INVOCATION
  /// (shaders/common.glsl): laid out as rows of at most maxComputeWorkGroupCount[0] groups, so
  /// that large images stay within the dispatch limits.
  template <class Push>
  void dispatchLinear(const Kernel& kernel, std::initializer_list<BufferView> buffers, const Push& push,
                      uint32_t groups) {
    const uint32_t row = std::max<uint32_t>(1, std::min<uint32_t>(groups, ctx_.device().max_workgroup_count[0]));
    dispatchRaw(kernel, buffers, &push, sizeof(Push), row, (groups + row - 1) / row, 1);
  }
  /// Like dispatch(), with the workgroup counts read on the device from `args` (3 uints at
  /// byte `offset`).
  void dispatchIndirectRaw(const Kernel& kernel, std::initializer_list<BufferView> buffers, const void* push,
                           std::size_t push_bytes, const Buffer& args, std::size_t offset = 0);
  template <class Push>
  void dispatchIndirect(const Kernel& kernel, std::initializer_list<BufferView> buffers, const Push& push,
                        const Buffer& args, std::size_t offset = 0) {
    dispatchIndirectRaw(kernel, buffers, &push, sizeof(Push), args, offset);
  }
  /// After submit(), `bytes` of `src` at `offset` land in `dst` (host memory that must outlive
  /// the submit).
  void download(const Buffer& src, void* dst, std::size_t bytes, std::size_t offset = 0);

  /// Submits everything recorded, waits, copies downloads to the host, and resets the batch
  /// for reuse (staging buffers are kept).
  void submit();
  /// The first half of submit(): submits what was recorded and returns at once, so the host
  /// can work while the device does. wait() (or anything recorded next) finishes it.
  void flush();
  /// The second half of submit(): waits for a flush(), copies downloads to the host, resets
  /// the batch. Does nothing when nothing is in flight.
  void wait();

  /// Whether timestamp() works: the queue writes timestamps, and VKPOSE_PROFILE_KERNELS (a
  /// submit per dispatch) is off.
  bool timestamps() const;
  /// Records a timestamp once everything recorded before it has finished; returns its index
  /// for millisecondsBetween(), valid after the next submit(). At most kMaxTimestamps per
  /// submit.
  uint32_t timestamp();
  /// Device time between two timestamps of the last submit, in milliseconds.
  double millisecondsBetween(uint32_t first, uint32_t second) const;
  static constexpr uint32_t kMaxTimestamps = 8;
  const GpuContext& context() const { return ctx_; }

 private:
  void begin();
  void bind(const Kernel& kernel, std::initializer_list<BufferView> buffers, const void* push, std::size_t push_bytes);
  void barrier();
  /// Barrier, and with VKPOSE_PROFILE_KERNELS a submit timed under the kernel's name.
  void afterDispatch(const Kernel& kernel);
  std::size_t staging(std::size_t bytes);

  const GpuContext& ctx_;
  vk::Device device_;
  vk::CommandBuffer cmd_;
  vk::Fence fence_;
  std::vector<vk::DescriptorPool> pools_;
  std::vector<vk::BufferView> views_;  ///< texel-buffer views of the recorded dispatches
  uint32_t sets_in_pool_ = 0;
  std::vector<Buffer> staging_;
  std::size_t staging_used_ = 0;
  struct PendingDownload {
    std::size_t staging;  // index into staging_ (which may reallocate)
    void* dst;
    std::size_t bytes;
  };
  std::vector<PendingDownload> downloads_;
  vk::QueryPool timestamp_pool_;
  vk::QueryPool busy_pool_;  ///< the submit's first and last timestamps (deviceMilliseconds)
  uint32_t timestamps_recorded_ = 0;
  std::vector<uint64_t> timestamp_values_;  ///< of the last submit
  bool recording_ = false;
  bool in_flight_ = false;
  bool profile_ = false;  ///< VKPOSE_PROFILE_KERNELS=1: submit after each dispatch and time it
};

/// Device time of every submit of `ctx` waited for so far, milliseconds (0 where the queue
/// writes no timestamps): the difference across a stage is the GPU's own share of its time.
double deviceMilliseconds(const GpuContext& ctx);

/// Milliseconds per kernel name accumulated while VKPOSE_PROFILE_KERNELS is set (the
/// per-dispatch submits make the total slower than a normal frame).
std::map<std::string, double>& kernelProfile();

/// Workgroup count that covers `n` items with groups of `size`.
inline uint32_t groupsFor(std::size_t n, uint32_t size) {
  return static_cast<uint32_t>((n + size - 1) / size);
}

/// The same as a 2D grid of at most kGridColumns columns (item = (y * kGridColumns + x) * size +
/// local), which the kernels dispatched so rely on.
struct Groups2D {
  uint32_t x = 1, y = 1;
};
inline Groups2D groups2DFor(std::size_t n, uint32_t size) {
  const uint32_t g = groupsFor(n, size);
  return {std::max<uint32_t>(std::min<uint32_t>(g, kGridColumns), 1u), (g + kGridColumns - 1u) / kGridColumns};
}

}  // namespace vkpose::gpu
