#pragma once
// One compute kernel: embedded SPIR-V, N buffer bindings (set 0, bindings 0..N-1), each a
// storage buffer or a uniform texel buffer, a push-constant block and specialization
// constants (constant_id 0, 1, ...).
#include <cstdint>
#include <vector>

#include "gpu/vulkan.hpp"
#include "vkpose_shader_ids.hpp"

namespace vkpose::gpu {

/// A binding read through texelFetch on a `utextureBuffer` rather than as a storage buffer:
/// on llvmpipe a texel fetch is a vector gather, while a storage-buffer load at a
/// per-invocation offset is a scalar loop over the lanes.
struct TexelBinding {
  uint32_t binding = 0;
  vk::Format format = vk::Format::eR32Uint;
};

class Kernel {
 public:
  Kernel(const GpuContext& ctx, ShaderId shader, uint32_t buffer_count, uint32_t push_constant_bytes,
         const std::vector<uint32_t>& specialization = {}, const std::vector<TexelBinding>& texel_bindings = {});
  ~Kernel();
  Kernel(const Kernel&) = delete;
  Kernel& operator=(const Kernel&) = delete;

  vk::Pipeline pipeline() const { return pipeline_; }
  vk::PipelineLayout layout() const { return layout_; }
  vk::DescriptorSetLayout setLayout() const { return set_layout_; }
  uint32_t bufferCount() const { return buffer_count_; }
  uint32_t pushConstantBytes() const { return push_bytes_; }
  /// Format of binding `b` when it is a texel buffer, eUndefined for a storage buffer.
  vk::Format texelFormat(uint32_t b) const { return b < texel_formats_.size() ? texel_formats_[b] : vk::Format::eUndefined; }
  const char* name() const;

 private:
  vk::Device device_;
  ShaderId shader_;
  uint32_t buffer_count_;
  uint32_t push_bytes_;
  std::vector<vk::Format> texel_formats_;
  vk::DescriptorSetLayout set_layout_;
  vk::PipelineLayout layout_;
  vk::Pipeline pipeline_;
};

}  // namespace vkpose::gpu
