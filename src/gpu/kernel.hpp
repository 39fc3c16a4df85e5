#pragma once
// One compute kernel: embedded SPIR-V, N storage-buffer bindings (set 0, bindings 0..N-1),
// a push-constant block and specialization constants (constant_id 0, 1, ...).
#include <cstdint>
#include <vector>

#include "gpu/vulkan.hpp"
#include "vkpose_shader_ids.hpp"

namespace vkpose::gpu {

class Kernel {
 public:
  Kernel(const GpuContext& ctx, ShaderId shader, uint32_t buffer_count, uint32_t push_constant_bytes,
         const std::vector<uint32_t>& specialization = {});
  ~Kernel();
  Kernel(const Kernel&) = delete;
  Kernel& operator=(const Kernel&) = delete;

  vk::Pipeline pipeline() const { return pipeline_; }
  vk::PipelineLayout layout() const { return layout_; }
  vk::DescriptorSetLayout setLayout() const { return set_layout_; }
  uint32_t bufferCount() const { return buffer_count_; }
  uint32_t pushConstantBytes() const { return push_bytes_; }
  const char* name() const;

 private:
  vk::Device device_;
  ShaderId shader_;
  uint32_t buffer_count_;
  uint32_t push_bytes_;
  vk::DescriptorSetLayout set_layout_;
  vk::PipelineLayout layout_;
  vk::Pipeline pipeline_;
};

}  // namespace vkpose::gpu
