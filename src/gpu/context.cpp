// Vulkan instance, device choice and compute queue (docs/pipeline.md, "The GPU layer").
#include <atomic>
#include <cstdlib>
#include <cstring>
#include <iostream>
#include <string>

#include "gpu/vulkan.hpp"
#include "vkpose/error.hpp"

#if defined(__SANITIZE_ADDRESS__)
#include <dlfcn.h>
#include <link.h>
#endif

namespace vkpose {
namespace {

constexpr const char* kNoVulkanHelp =
    "install a Vulkan driver: 'apt-get install mesa-vulkan-drivers' gives lavapipe (runs on the "
    "CPU); on a GPU machine install its vendor's Vulkan driver";

std::string versionString(uint32_t v) {
  return std::to_string(VK_API_VERSION_MAJOR(v)) + "." + std::to_string(VK_API_VERSION_MINOR(v)) +
         "." + std::to_string(VK_API_VERSION_PATCH(v));
}

std::string typeName(vk::PhysicalDeviceType t) {
  switch (t) {
    case vk::PhysicalDeviceType::eDiscreteGpu: return "discrete";
    case vk::PhysicalDeviceType::eIntegratedGpu: return "integrated";
    case vk::PhysicalDeviceType::eVirtualGpu: return "virtual";
    case vk::PhysicalDeviceType::eCpu: return "cpu";
    default: return "other";
  }
}

int typeRank(const std::string& type) {
  if (type == "discrete") return 0;
  if (type == "integrated") return 1;
  if (type == "virtual") return 2;
  if (type == "cpu") return 3;
  return 4;
}

/// Validation errors of every context of this process (tests fail the test that caused one).
std::atomic<uint32_t> g_process_validation_errors{0};

bool layerAvailable(const char* name) {
  for (const auto& layer : vk::enumerateInstanceLayerProperties())
    if (std::strcmp(layer.layerName, name) == 0) return true;
  return false;
}

vk::Instance createInstance(bool validation) {
  vk::ApplicationInfo app{.pApplicationName = "vkpose",
                          .applicationVersion = VK_MAKE_API_VERSION(0, 0, 1, 0),
                          .pEngineName = "vkpose",
                          .apiVersion = VK_API_VERSION_1_2};
  std::vector<const char*> layers;
  std::vector<const char*> extensions;
  if (validation) {
    if (!layerAvailable("VK_LAYER_KHRONOS_validation"))
      throw DeviceError(
          "Vulkan validation was requested but VK_LAYER_KHRONOS_validation is missing: "
          "apt-get install vulkan-validationlayers");
    layers.push_back("VK_LAYER_KHRONOS_validation");
    extensions.push_back(VK_EXT_DEBUG_UTILS_EXTENSION_NAME);
  }
  vk::InstanceCreateInfo info{.pApplicationInfo = &app,
                              .enabledLayerCount = static_cast<uint32_t>(layers.size()),
                              .ppEnabledLayerNames = layers.data(),
                              .enabledExtensionCount = static_cast<uint32_t>(extensions.size()),
                              .ppEnabledExtensionNames = extensions.data()};
  try {
    return vk::createInstance(info);
  } catch (const vk::SystemError& e) {
    throw DeviceError(std::string("cannot create a Vulkan instance (") + e.what() + "): " +
                      kNoVulkanHelp);
  }
}

GpuDeviceInfo describe(vk::PhysicalDevice pd, uint32_t index) {
  GpuDeviceInfo info;
  info.index = index;
  auto chain = pd.getProperties2<vk::PhysicalDeviceProperties2, vk::PhysicalDeviceSubgroupProperties,
                                 vk::PhysicalDeviceDriverProperties>();
  const auto& props = chain.get<vk::PhysicalDeviceProperties2>().properties;
  const auto& driver = chain.get<vk::PhysicalDeviceDriverProperties>();
  info.name = props.deviceName.data();
  info.type = typeName(props.deviceType);
  info.api_version = versionString(props.apiVersion);
  info.driver = std::string(driver.driverName.data()) + " " + driver.driverInfo.data();
  info.max_storage_buffer_range = props.limits.maxStorageBufferRange;
  info.max_texel_buffer_elements = props.limits.maxTexelBufferElements;
  info.max_shared_memory = props.limits.maxComputeSharedMemorySize;
  info.subgroup_size = chain.get<vk::PhysicalDeviceSubgroupProperties>().subgroupSize;
  info.max_workgroup_invocations = props.limits.maxComputeWorkGroupInvocations;
  for (int i = 0; i < 3; ++i) info.max_workgroup_count[i] = props.limits.maxComputeWorkGroupCount[i];
  auto mem = pd.getMemoryProperties();
  for (uint32_t h = 0; h < mem.memoryHeapCount; ++h)
    if (mem.memoryHeaps[h].flags & vk::MemoryHeapFlagBits::eDeviceLocal)
      info.device_local_memory = std::max<uint64_t>(info.device_local_memory, mem.memoryHeaps[h].size);

  auto features = pd.getFeatures2<vk::PhysicalDeviceFeatures2, vk::PhysicalDeviceVulkan11Features,
                                  vk::PhysicalDeviceVulkan12Features>();
  const auto& f11 = features.get<vk::PhysicalDeviceVulkan11Features>();
  const auto& f12 = features.get<vk::PhysicalDeviceVulkan12Features>();
  std::string missing;
  if (props.apiVersion < VK_API_VERSION_1_2) missing += " Vulkan 1.2";
  if (!f12.storageBuffer8BitAccess) missing += " storageBuffer8BitAccess";
  if (!f11.storageBuffer16BitAccess) missing += " storageBuffer16BitAccess";
  bool has_compute = false;
  for (const auto& q : pd.getQueueFamilyProperties())
    if (q.queueFlags & vk::QueueFlagBits::eCompute) has_compute = true;
  if (!has_compute) missing += " compute queue";
  info.int64_atomics = features.get<vk::PhysicalDeviceFeatures2>().features.shaderInt64 && f12.shaderBufferInt64Atomics;
  info.usable = missing.empty();
  info.missing = missing.empty() ? "" : missing.substr(1);
  return info;
}

VKAPI_ATTR VkBool32 VKAPI_CALL onValidationMessage(VkDebugUtilsMessageSeverityFlagBitsEXT severity,
                                                   VkDebugUtilsMessageTypeFlagsEXT,
                                                   const VkDebugUtilsMessengerCallbackDataEXT* data,
                                                   void* user) {
  if (severity & VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT) {
    static_cast<gpu::ContextState*>(user)->validation_errors++;
    g_process_validation_errors++;
    std::cerr << "vkpose: Vulkan validation: " << data->pMessage << "\n";
  }
  return VK_FALSE;
}

/// Under AddressSanitizer only: keeps every shared object loaded now (the Vulkan driver, its
/// LLVM, layers) loaded for the life of the process. The loader unloads the driver when the
/// last instance goes, and LeakSanitizer's exit-time report then shows the driver's own
/// leftovers as "<unknown module>", which no suppression can name. Pinned, they carry their
/// library's name and tests/lsan.supp matches them. Release builds do nothing here.
void pinLoadedDrivers() {
#if defined(__SANITIZE_ADDRESS__)
  dl_iterate_phdr(
      [](dl_phdr_info* info, std::size_t, void*) {
        if (info->dlpi_name && info->dlpi_name[0] == '/')
          dlopen(info->dlpi_name, RTLD_LAZY | RTLD_NOLOAD | RTLD_NODELETE);
        return 0;
      },
      nullptr);
#endif
}

bool envFlag(const char* name) {
  const char* v = std::getenv(name);
  return v && *v && std::strcmp(v, "0") != 0;
}

}  // namespace

std::vector<GpuDeviceInfo> listGpuDevices() {
  vk::Instance instance = createInstance(false);
  std::vector<GpuDeviceInfo> out;
  auto devices = instance.enumeratePhysicalDevices();
  for (uint32_t i = 0; i < devices.size(); ++i) out.push_back(describe(devices[i], i));
  pinLoadedDrivers();
  instance.destroy();
  return out;
}

std::size_t chooseGpuDevice(const std::vector<GpuDeviceInfo>& devices, const GpuOptions& options) {
  if (devices.empty()) throw DeviceError(std::string("no Vulkan device found: ") + kNoVulkanHelp);
  std::optional<int> wanted = options.device_index;
  if (!wanted) {
    if (const char* env = std::getenv("VKPOSE_DEVICE"); env && *env) {
      char* end = nullptr;
      long v = std::strtol(env, &end, 10);
      if (*end != '\0' || v < 0)
        throw InputError(std::string("VKPOSE_DEVICE='") + env + "' is not a device index (see 'vkpose info')");
      wanted = static_cast<int>(v);
    }
  }
  if (wanted) {
    if (*wanted < 0 || static_cast<std::size_t>(*wanted) >= devices.size())
      throw InputError("Vulkan device " + std::to_string(*wanted) + " does not exist: there are " +
                       std::to_string(devices.size()) + " (see 'vkpose info')");
    const auto& d = devices[static_cast<std::size_t>(*wanted)];
    if (!d.usable)
      throw DeviceError("Vulkan device " + std::to_string(*wanted) + " (" + d.name + ") lacks " + d.missing);
    return static_cast<std::size_t>(*wanted);
  }
  std::size_t best = devices.size();
  for (std::size_t i = 0; i < devices.size(); ++i) {
    if (!devices[i].usable) continue;
    if (best == devices.size() || typeRank(devices[i].type) < typeRank(devices[best].type)) best = i;
  }
  if (best == devices.size())
    throw DeviceError("no usable Vulkan device (" + devices[0].name + " lacks " + devices[0].missing +
                      "): " + kNoVulkanHelp);
  return best;
}

namespace {
/// The first type allowed by type_bits with all of flags, or -1.
int firstMemoryType(const vk::PhysicalDeviceMemoryProperties& memory, uint32_t type_bits,
                    vk::MemoryPropertyFlags flags) {
  for (uint32_t i = 0; i < memory.memoryTypeCount && i < 32; ++i)
    if ((type_bits & (1u << i)) && (memory.memoryTypes[i].propertyFlags & flags) == flags) return static_cast<int>(i);
  return -1;
}
}  // namespace

uint32_t gpu::chooseMemoryType(const vk::PhysicalDeviceMemoryProperties& memory, uint32_t type_bits,
                               bool host_visible, const std::string& device_name) {
  using F = vk::MemoryPropertyFlagBits;
  const vk::MemoryPropertyFlags mapped = F::eHostVisible | F::eHostCoherent;
  int i = host_visible ? firstMemoryType(memory, type_bits, mapped | F::eHostCached)
                       : firstMemoryType(memory, type_bits, F::eDeviceLocal);
  if (i < 0 && host_visible) i = firstMemoryType(memory, type_bits, mapped);
  if (i < 0)
    throw DeviceError(std::string("no Vulkan memory type for ") + (host_visible ? "mapped" : "device-local") +
                      " buffers on " + device_name);
  return static_cast<uint32_t>(i);
}

GpuContext::GpuContext(const GpuOptions& options) : state_(std::make_unique<gpu::ContextState>()) {
  auto& s = *state_;
  const bool validation = options.validation || envFlag("VKPOSE_VALIDATION");
  s.instance = createInstance(validation);
  try {
    auto physicals = s.instance.enumeratePhysicalDevices();
    std::vector<GpuDeviceInfo> infos;
    for (uint32_t i = 0; i < physicals.size(); ++i) infos.push_back(describe(physicals[i], i));
    const std::size_t chosen = chooseGpuDevice(infos, options);
    s.physical = physicals[chosen];
    s.info = infos[chosen];
    s.memory = s.physical.getMemoryProperties();
    s.memory_limit = s.info.device_local_memory;
    if (const char* env = std::getenv("VKPOSE_GPU_MEMORY_LIMIT_MIB"); env && *env) {
      char* end = nullptr;
      const unsigned long long mib = std::strtoull(env, &end, 10);
      if (*end != '\0' || mib == 0)
        throw InputError(std::string("VKPOSE_GPU_MEMORY_LIMIT_MIB='") + env + "' is not a positive number of MiB");
      s.memory_limit = std::min<uint64_t>(s.memory_limit, mib << 20);
    }

    if (validation) {
      s.create_messenger = reinterpret_cast<PFN_vkCreateDebugUtilsMessengerEXT>(
          s.instance.getProcAddr("vkCreateDebugUtilsMessengerEXT"));
      s.destroy_messenger = reinterpret_cast<PFN_vkDestroyDebugUtilsMessengerEXT>(
          s.instance.getProcAddr("vkDestroyDebugUtilsMessengerEXT"));
      VkDebugUtilsMessengerCreateInfoEXT ci{};
      ci.sType = VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT;
      ci.messageSeverity = VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT |
                           VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT;
      ci.messageType = VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT |
                       VK_DEBUG_UTILS_MESSAGE_TYPE_GENERAL_BIT_EXT;
      ci.pfnUserCallback = onValidationMessage;
      ci.pUserData = &s;
      VkDebugUtilsMessengerEXT m = VK_NULL_HANDLE;
      if (s.create_messenger && s.create_messenger(s.instance, &ci, nullptr, &m) == VK_SUCCESS)
        s.messenger = m;
    }

    auto families = s.physical.getQueueFamilyProperties();
    s.queue_family = static_cast<uint32_t>(families.size());
    for (uint32_t i = 0; i < families.size(); ++i)
      if (families[i].queueFlags & vk::QueueFlagBits::eCompute) {
        s.queue_family = i;
        break;
      }
    if (s.queue_family < families.size() && families[s.queue_family].timestampValidBits > 0) {
      const uint32_t bits = families[s.queue_family].timestampValidBits;
      s.timestamp_mask = bits >= 64 ? ~uint64_t{0} : (uint64_t{1} << bits) - 1;
      s.timestamp_period_ns = s.physical.getProperties().limits.timestampPeriod;
    }
    const float priority = 1.0f;
    vk::DeviceQueueCreateInfo queue_info{.queueFamilyIndex = s.queue_family,
                                         .queueCount = 1,
                                         .pQueuePriorities = &priority};
    vk::PhysicalDeviceVulkan11Features f11{.storageBuffer16BitAccess = VK_TRUE};
    vk::PhysicalDeviceVulkan12Features f12{.pNext = &f11, .storageBuffer8BitAccess = VK_TRUE};
    // 64-bit atomics let the renderer keep depth and triangle id in one atomicMin.
    const bool int64 = s.info.int64_atomics;
    f12.shaderBufferInt64Atomics = int64 ? VK_TRUE : VK_FALSE;
    vk::PhysicalDeviceFeatures2 core{.pNext = &f12};
    core.features.shaderInt64 = int64 ? VK_TRUE : VK_FALSE;
    vk::DeviceCreateInfo device_info{.pNext = &core,
                                     .queueCreateInfoCount = 1,
                                     .pQueueCreateInfos = &queue_info};
    s.device = s.physical.createDevice(device_info);
    s.queue = s.device.getQueue(s.queue_family, 0);
    s.command_pool = s.device.createCommandPool(
        {.flags = vk::CommandPoolCreateFlagBits::eResetCommandBuffer, .queueFamilyIndex = s.queue_family});
    pinLoadedDrivers();
  } catch (const vk::SystemError& e) {
    throw DeviceError(std::string("Vulkan device set-up failed: ") + e.what());
  }
}

GpuContext::~GpuContext() {
  auto& s = *state_;
  if (s.device) {
    s.device.waitIdle();
    s.device.destroyCommandPool(s.command_pool);
    s.device.destroy();
  }
  if (s.messenger && s.destroy_messenger) s.destroy_messenger(s.instance, s.messenger, nullptr);
  if (s.instance) s.instance.destroy();
}

const GpuDeviceInfo& GpuContext::device() const { return state_->info; }
uint32_t GpuContext::validationErrors() const { return state_->validation_errors.load(); }
uint32_t GpuContext::processValidationErrors() { return g_process_validation_errors.load(); }

}  // namespace vkpose
