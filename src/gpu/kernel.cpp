#include "gpu/kernel.hpp"

#include "vkpose/error.hpp"

namespace vkpose::gpu {

Kernel::Kernel(const GpuContext& ctx, ShaderId shader, uint32_t buffer_count, uint32_t push_constant_bytes,
               const std::vector<uint32_t>& specialization, const std::vector<TexelBinding>& texel_bindings)
    : device_(ctx.state().device),
      shader_(shader),
      buffer_count_(buffer_count),
      push_bytes_(push_constant_bytes),
      texel_formats_(buffer_count, vk::Format::eUndefined) {
  const auto& code = embeddedShader(shader);
  for (const auto& t : texel_bindings) texel_formats_.at(t.binding) = t.format;
  std::vector<vk::DescriptorSetLayoutBinding> bindings;
  for (uint32_t b = 0; b < buffer_count; ++b)
    bindings.push_back({.binding = b,
                        .descriptorType = texel_formats_[b] == vk::Format::eUndefined
                                              ? vk::DescriptorType::eStorageBuffer
                                              : vk::DescriptorType::eUniformTexelBuffer,
                        .descriptorCount = 1,
                        .stageFlags = vk::ShaderStageFlagBits::eCompute});
  set_layout_ = device_.createDescriptorSetLayout(
      {.bindingCount = static_cast<uint32_t>(bindings.size()), .pBindings = bindings.data()});
  vk::PushConstantRange push{.stageFlags = vk::ShaderStageFlagBits::eCompute, .offset = 0, .size = push_bytes_};
  layout_ = device_.createPipelineLayout({.setLayoutCount = 1,
                                          .pSetLayouts = &set_layout_,
                                          .pushConstantRangeCount = push_bytes_ ? 1u : 0u,
                                          .pPushConstantRanges = &push});
  vk::ShaderModule module =
      device_.createShaderModule({.codeSize = code.word_count * sizeof(uint32_t), .pCode = code.words});
  std::vector<vk::SpecializationMapEntry> entries;
  for (uint32_t i = 0; i < specialization.size(); ++i)
    entries.push_back({.constantID = i, .offset = i * 4u, .size = 4});
  vk::SpecializationInfo spec{.mapEntryCount = static_cast<uint32_t>(entries.size()),
                              .pMapEntries = entries.data(),
                              .dataSize = specialization.size() * sizeof(uint32_t),
                              .pData = specialization.data()};
  vk::ComputePipelineCreateInfo info{
      .stage = {.stage = vk::ShaderStageFlagBits::eCompute,
                .module = module,
                .pName = "main",
                .pSpecializationInfo = specialization.empty() ? nullptr : &spec},
      .layout = layout_};
  auto result = device_.createComputePipeline(nullptr, info);
  device_.destroyShaderModule(module);
  if (result.result != vk::Result::eSuccess)
    throw DeviceError(std::string("cannot build the compute pipeline of kernel ") + std::string(code.name));
  pipeline_ = result.value;
}

Kernel::~Kernel() {
  device_.destroyPipeline(pipeline_);
  device_.destroyPipelineLayout(layout_);
  device_.destroyDescriptorSetLayout(set_layout_);
}

const char* Kernel::name() const { return embeddedShader(shader_).name.data(); }

}  // namespace vkpose::gpu
