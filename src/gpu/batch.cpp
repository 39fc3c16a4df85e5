#include "gpu/batch.hpp"

#include <chrono>
#include <cstdlib>
#include <cstring>
#include <string>

#include "vkpose/error.hpp"

namespace vkpose::gpu {
namespace {
constexpr uint32_t kSetsPerPool = 256;
constexpr uint32_t kMaxBindings = 16;

std::size_t texelBytes(vk::Format format) {
  switch (format) {
    case vk::Format::eR16Uint: return 2;
    case vk::Format::eR32Uint:
    case vk::Format::eR32Sint: return 4;
    case vk::Format::eR32G32Uint: return 8;
    case vk::Format::eR32G32B32A32Uint: return 16;
    default: throw std::logic_error("gpu::Batch: unsupported texel-buffer format");
  }
}
}  // namespace

Batch::Batch(const GpuContext& ctx) : ctx_(ctx), device_(ctx.state().device) {
  const char* env = std::getenv("VKPOSE_PROFILE_KERNELS");
  profile_ = env && *env && std::string(env) != "0";
  cmd_ = device_.allocateCommandBuffers({.commandPool = ctx.state().command_pool,
                                         .level = vk::CommandBufferLevel::ePrimary,
                                         .commandBufferCount = 1})[0];
  fence_ = device_.createFence({});
}

Batch::~Batch() {
  // Nothing may be destroyed under work still running.
  if (in_flight_) (void)device_.waitForFences(fence_, VK_TRUE, UINT64_MAX);
  if (timestamp_pool_) device_.destroyQueryPool(timestamp_pool_);
  if (busy_pool_) device_.destroyQueryPool(busy_pool_);
  device_.destroyFence(fence_);
  device_.freeCommandBuffers(ctx_.state().command_pool, cmd_);
  for (auto pool : pools_) device_.destroyDescriptorPool(pool);
  for (auto view : views_) device_.destroyBufferView(view);
}

void Batch::begin() {
  if (recording_) return;
  wait();  // the command buffer, staging buffers and descriptor sets of a flushed batch
  cmd_.begin({.flags = vk::CommandBufferUsageFlagBits::eOneTimeSubmit});
  recording_ = true;
  if (ctx_.state().timestamp_mask != 0) {
    if (!busy_pool_) busy_pool_ = device_.createQueryPool({.queryType = vk::QueryType::eTimestamp, .queryCount = 2});
    cmd_.resetQueryPool(busy_pool_, 0, 2);
    cmd_.writeTimestamp(vk::PipelineStageFlagBits::eTopOfPipe, busy_pool_, 0);
  }
}

double deviceMilliseconds(const GpuContext& ctx) { return static_cast<double>(ctx.state().device_ns.load()) * 1e-6; }

void Batch::barrier() {
  vk::MemoryBarrier b{.srcAccessMask = vk::AccessFlagBits::eShaderWrite | vk::AccessFlagBits::eTransferWrite,
                      .dstAccessMask = vk::AccessFlagBits::eShaderRead | vk::AccessFlagBits::eShaderWrite |
                                       vk::AccessFlagBits::eTransferRead | vk::AccessFlagBits::eTransferWrite |
                                       vk::AccessFlagBits::eIndirectCommandRead};
  const auto stages = vk::PipelineStageFlagBits::eComputeShader | vk::PipelineStageFlagBits::eTransfer |
                      vk::PipelineStageFlagBits::eDrawIndirect;
  cmd_.pipelineBarrier(stages, stages, {}, b, {}, {});
}

std::size_t Batch::staging(std::size_t bytes) {
  if (staging_used_ == staging_.size()) staging_.emplace_back();
  staging_[staging_used_].reserve(ctx_, bytes, MemoryKind::HostVisible);
  return staging_used_++;
}

void Batch::upload(const Buffer& dst, const void* data, std::size_t bytes, std::size_t offset) {
  if (bytes == 0) return;
  std::memcpy(uploadInPlace(dst, bytes, offset), data, bytes);
}

void* Batch::uploadInPlace(const Buffer& dst, std::size_t bytes, std::size_t offset) {
  if (bytes == 0) return nullptr;
  if (offset + bytes > dst.size()) throw std::out_of_range("gpu::Batch::upload past the end of a buffer");
  begin();
  Buffer& s = staging_[staging(bytes)];
  cmd_.copyBuffer(s.handle(), dst.handle(), vk::BufferCopy{.srcOffset = 0, .dstOffset = offset, .size = bytes});
  barrier();
  return s.mapped();
}

void Batch::fill(const Buffer& dst, uint32_t value, std::size_t bytes, std::size_t offset) {
  begin();
  cmd_.fillBuffer(dst.handle(), offset, bytes == VK_WHOLE_SIZE ? VK_WHOLE_SIZE : (bytes + 3) / 4 * 4, value);
  barrier();
}

void Batch::bind(const Kernel& kernel, std::initializer_list<BufferView> buffers, const void* push,
                 std::size_t push_bytes) {
  if (buffers.size() != kernel.bufferCount() || buffers.size() > kMaxBindings)
    throw std::logic_error(std::string("kernel ") + kernel.name() + ": wrong number of buffers");
  if (push_bytes != kernel.pushConstantBytes())
    throw std::logic_error(std::string("kernel ") + kernel.name() + ": push-constant size mismatch");
  begin();
  if (pools_.empty() || sets_in_pool_ == kSetsPerPool) {
    const vk::DescriptorPoolSize sizes[2] = {
        {.type = vk::DescriptorType::eStorageBuffer, .descriptorCount = kSetsPerPool * kMaxBindings},
        {.type = vk::DescriptorType::eUniformTexelBuffer, .descriptorCount = kSetsPerPool * kMaxBindings}};
    pools_.push_back(device_.createDescriptorPool({.maxSets = kSetsPerPool, .poolSizeCount = 2, .pPoolSizes = sizes}));
    sets_in_pool_ = 0;
  }
  auto layout = kernel.setLayout();
  vk::DescriptorSet set =
      device_.allocateDescriptorSets({.descriptorPool = pools_.back(), .descriptorSetCount = 1, .pSetLayouts = &layout})[0];
  ++sets_in_pool_;
  std::vector<vk::DescriptorBufferInfo> infos(buffers.size());
  std::vector<vk::BufferView> views(buffers.size());
  std::vector<vk::WriteDescriptorSet> writes;
  uint32_t i = 0;
  for (const auto& v : buffers) {
    const std::size_t range = std::max<std::size_t>(v.range ? v.range : v.buffer->size() - v.offset, 4);
    const vk::Format format = kernel.texelFormat(i);
    if (format == vk::Format::eUndefined) {
      if (range > ctx_.device().max_storage_buffer_range)
        throw DeviceError(std::string("kernel ") + kernel.name() + ": a binding exceeds maxStorageBufferRange");
      infos[i] = vk::DescriptorBufferInfo{.buffer = v.buffer->handle(), .offset = v.offset, .range = range};
      writes.push_back({.dstSet = set,
                        .dstBinding = i,
                        .descriptorCount = 1,
                        .descriptorType = vk::DescriptorType::eStorageBuffer,
                        .pBufferInfo = &infos[i]});
    } else {
      const std::size_t texel = texelBytes(format);
      if (range / texel > ctx_.device().max_texel_buffer_elements)
        throw DeviceError(std::string("kernel ") + kernel.name() + ": a binding exceeds maxTexelBufferElements");
      views[i] = device_.createBufferView(
          {.buffer = v.buffer->handle(), .format = format, .offset = v.offset, .range = range / texel * texel});
      views_.push_back(views[i]);
      writes.push_back({.dstSet = set,
                        .dstBinding = i,
                        .descriptorCount = 1,
                        .descriptorType = vk::DescriptorType::eUniformTexelBuffer,
                        .pTexelBufferView = &views[i]});
    }
    ++i;
  }
  device_.updateDescriptorSets(writes, {});
  cmd_.bindPipeline(vk::PipelineBindPoint::eCompute, kernel.pipeline());
  cmd_.bindDescriptorSets(vk::PipelineBindPoint::eCompute, kernel.layout(), 0, set, {});
  if (push_bytes)
    cmd_.pushConstants(kernel.layout(), vk::ShaderStageFlagBits::eCompute, 0, static_cast<uint32_t>(push_bytes), push);
}

void Batch::dispatchRaw(const Kernel& kernel, std::initializer_list<BufferView> buffers, const void* push,
                     std::size_t push_bytes, uint32_t gx, uint32_t gy, uint32_t gz) {
  if (gx == 0 || gy == 0 || gz == 0) return;
  const auto& limits = ctx_.device();
  if (gx > limits.max_workgroup_count[0] || gy > limits.max_workgroup_count[1] || gz > limits.max_workgroup_count[2])
    throw DeviceError(std::string("kernel ") + kernel.name() + ": too many workgroups for " + limits.name);
  bind(kernel, buffers, push, push_bytes);
  cmd_.dispatch(gx, gy, gz);
  afterDispatch(kernel);
}

void Batch::afterDispatch(const Kernel& kernel) {
  barrier();
  if (!profile_) return;
  const auto t0 = std::chrono::steady_clock::now();
  submit();
  kernelProfile()[kernel.name()] += std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

std::map<std::string, double>& kernelProfile() {
  static std::map<std::string, double> profile;
  return profile;
}

void Batch::dispatchIndirectRaw(const Kernel& kernel, std::initializer_list<BufferView> buffers, const void* push,
                             std::size_t push_bytes, const Buffer& args, std::size_t offset) {
  bind(kernel, buffers, push, push_bytes);
  cmd_.dispatchIndirect(args.handle(), offset);
  afterDispatch(kernel);
}

void Batch::download(const Buffer& src, void* dst, std::size_t bytes, std::size_t offset) {
  if (bytes == 0) return;
  if (offset + bytes > src.size()) throw std::out_of_range("gpu::Batch::download past the end of a buffer");
  begin();
  const std::size_t index = staging(bytes);
  cmd_.copyBuffer(src.handle(), staging_[index].handle(), vk::BufferCopy{.srcOffset = offset, .dstOffset = 0, .size = bytes});
  downloads_.push_back({index, dst, bytes});
}

bool Batch::timestamps() const { return ctx_.state().timestamp_mask != 0 && !profile_; }

uint32_t Batch::timestamp() {
  if (!timestamps()) throw std::logic_error("gpu::Batch::timestamp: this queue writes no timestamps");
  if (timestamps_recorded_ == kMaxTimestamps) throw std::logic_error("gpu::Batch::timestamp: too many in one submit");
  if (!timestamp_pool_)
    timestamp_pool_ = device_.createQueryPool({.queryType = vk::QueryType::eTimestamp, .queryCount = kMaxTimestamps});
  begin();
  if (timestamps_recorded_ == 0) cmd_.resetQueryPool(timestamp_pool_, 0, kMaxTimestamps);
  cmd_.writeTimestamp(vk::PipelineStageFlagBits::eBottomOfPipe, timestamp_pool_, timestamps_recorded_);
  return timestamps_recorded_++;
}

double Batch::millisecondsBetween(uint32_t first, uint32_t second) const {
  if (first >= timestamp_values_.size() || second >= timestamp_values_.size())
    throw std::logic_error("gpu::Batch::millisecondsBetween: no such timestamp in the last submit");
  const auto& state = ctx_.state();
  const uint64_t ticks = (timestamp_values_[second] - timestamp_values_[first]) & state.timestamp_mask;
  return static_cast<double>(ticks) * state.timestamp_period_ns * 1e-6;
}

void Batch::submit() {
  flush();
  wait();
}

void Batch::flush() {
  if (!recording_) return;
  // Host reads of downloads and of host-visible buffers the kernels wrote.
  vk::MemoryBarrier to_host{.srcAccessMask = vk::AccessFlagBits::eTransferWrite | vk::AccessFlagBits::eShaderWrite,
                            .dstAccessMask = vk::AccessFlagBits::eHostRead};
  cmd_.pipelineBarrier(vk::PipelineStageFlagBits::eTransfer | vk::PipelineStageFlagBits::eComputeShader,
                       vk::PipelineStageFlagBits::eHost, {}, to_host, {}, {});
  if (busy_pool_) cmd_.writeTimestamp(vk::PipelineStageFlagBits::eBottomOfPipe, busy_pool_, 1);
  cmd_.end();
  recording_ = false;
  vk::SubmitInfo submit{.commandBufferCount = 1, .pCommandBuffers = &cmd_};
  ctx_.state().queue.submit(submit, fence_);
  in_flight_ = true;
}

void Batch::wait() {
  if (!in_flight_) return;
  in_flight_ = false;
  if (device_.waitForFences(fence_, VK_TRUE, UINT64_MAX) != vk::Result::eSuccess)
    throw DeviceError("waiting for the GPU failed");
  device_.resetFences(fence_);
  timestamp_values_.assign(timestamps_recorded_, 0);
  if (timestamps_recorded_ > 0 &&
      device_.getQueryPoolResults(timestamp_pool_, 0, timestamps_recorded_, timestamp_values_.size() * 8,
                                  timestamp_values_.data(), 8, vk::QueryResultFlagBits::e64) != vk::Result::eSuccess)
    throw DeviceError("reading the GPU timestamps failed");
  timestamps_recorded_ = 0;
  if (busy_pool_) {
    uint64_t ends[2] = {0, 0};
    if (device_.getQueryPoolResults(busy_pool_, 0, 2, sizeof ends, ends, 8, vk::QueryResultFlagBits::e64) ==
        vk::Result::eSuccess) {
      auto& state = ctx_.state();
      const uint64_t ticks = (ends[1] - ends[0]) & state.timestamp_mask;
      state.device_ns += static_cast<uint64_t>(static_cast<double>(ticks) * state.timestamp_period_ns);
    }
  }
  for (const auto& d : downloads_) std::memcpy(d.dst, staging_[d.staging].mapped(), d.bytes);
  downloads_.clear();
  staging_used_ = 0;
  for (auto pool : pools_) device_.resetDescriptorPool(pool);
  if (pools_.size() > 1) {
    for (std::size_t i = 1; i < pools_.size(); ++i) device_.destroyDescriptorPool(pools_[i]);
    pools_.resize(1);
  }
  sets_in_pool_ = 0;
  for (auto view : views_) device_.destroyBufferView(view);
  views_.clear();
  cmd_.reset();
}

}  // namespace vkpose::gpu
