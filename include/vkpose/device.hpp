#pragma once
// The Vulkan device vkpose runs its kernels on: a real GPU when there is one, Mesa's lavapipe
// (llvmpipe) on the CPU otherwise. The same kernels run on both.
#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace vkpose {

/// What vkpose needs to know about one Vulkan physical device.
struct GpuDeviceInfo {
  uint32_t index = 0;                 ///< position in the Vulkan enumeration (`--device N`)
  std::string name;                   ///< e.g. "llvmpipe (LLVM 15.0.6, 256 bits)"
  std::string type;                   ///< "discrete", "integrated", "virtual", "cpu", "other"
  std::string api_version;            ///< "1.3.230"
  std::string driver;                 ///< driver name and info, when the driver reports them
  uint64_t max_storage_buffer_range = 0;  ///< bytes one storage-buffer binding may span
  uint64_t max_texel_buffer_elements = 0; ///< texels one texel-buffer binding may span
  uint32_t max_shared_memory = 0;         ///< bytes of shared memory per workgroup
  uint32_t subgroup_size = 0;             ///< lanes per subgroup
  uint32_t max_workgroup_invocations = 0;
  std::array<uint32_t, 3> max_workgroup_count{};
  uint64_t device_local_memory = 0;       ///< bytes in the largest device-local heap
  bool int64_atomics = false;             ///< 64-bit storage-buffer atomics (the template renderer)
  bool usable = false;                    ///< has the features vkpose needs (8/16-bit storage)
  std::string missing;                    ///< when not usable: what is missing
};

struct GpuOptions {
  /// Vulkan device index; unset: the VKPOSE_DEVICE environment variable, else the first
  /// discrete GPU, then integrated, then virtual, then the CPU (lavapipe).
  std::optional<int> device_index;
  /// Enable the Khronos validation layer (also with VKPOSE_VALIDATION=1).
  bool validation = false;
};

/// Lists every Vulkan device with the limits that matter. Throws DeviceError when Vulkan
/// itself is missing.
std::vector<GpuDeviceInfo> listGpuDevices();

/// Picks a device as GpuOptions describes, among `devices`; returns its position in `devices`.
std::size_t chooseGpuDevice(const std::vector<GpuDeviceInfo>& devices, const GpuOptions& options);

namespace gpu {
struct ContextState;
}

/// Owns the Vulkan instance, the chosen device and its compute queue.
class GpuContext {
 public:
  explicit GpuContext(const GpuOptions& options = {});
  ~GpuContext();
  GpuContext(const GpuContext&) = delete;
  GpuContext& operator=(const GpuContext&) = delete;

  const GpuDeviceInfo& device() const;
  /// Number of validation-layer errors seen so far (0 unless validation is on).
  uint32_t validationErrors() const;
  /// Validation-layer errors of all contexts of this process so far, those already destroyed
  /// included (tests fail the test during which this grows).
  static uint32_t processValidationErrors();

  gpu::ContextState& state() const { return *state_; }

 private:
  std::unique_ptr<gpu::ContextState> state_;
};

}  // namespace vkpose
