// Template banks cached between runs (bank_cache.hpp).
#include "vkpose/bank.hpp"

#include <cstdlib>
#include <filesystem>

#include <fmt/format.h>
#include <unistd.h>

#include "vkpose/device.hpp"
#include "vkpose/error.hpp"
#include "vkpose/geometry.hpp"

namespace vkpose {

std::string defaultBankCacheDir() {
  if (const char* dir = std::getenv("VKPOSE_CACHE_DIR"); dir && *dir) return dir;
  if (const char* xdg = std::getenv("XDG_CACHE_HOME"); xdg && *xdg) return std::string(xdg) + "/vkpose/banks";
  if (const char* home = std::getenv("HOME"); home && *home) return std::string(home) + "/.cache/vkpose/banks";
  return {};
}

CachedBank loadOrTrainBank(const GpuContext& ctx, const Mesh& mesh, const TrainingParams& params,
                           const std::vector<TrainingView>& views, const std::string& cache_dir,
                           const TrainingProgress& progress) {
  CachedBank out;
  if (!cache_dir.empty())
    out.path = fmt::format("{}/{}-{:016x}.vkpb", cache_dir, mesh.name.empty() ? "object" : mesh.name,
                           trainingKey(mesh, params, views));
  std::error_code ec;
  if (!out.path.empty() && std::filesystem::is_regular_file(out.path, ec)) {
    try {
      out.bank = loadBank(out.path);
      out.from_cache = true;
      return out;
    } catch (const InputError&) {
      // Damaged or from another vkpose: train it again below and replace it.
    }
  }
  out.bank = trainTemplatesFromViews(ctx, mesh, params, views, progress);
  if (out.path.empty()) return out;
  std::filesystem::create_directories(cache_dir, ec);
  if (ec) throw InputError(fmt::format("cannot create the bank cache folder {}: {}", cache_dir, ec.message()));
  const std::string partial = fmt::format("{}.{}.part", out.path, ::getpid());
  saveBank(out.bank, partial);
  std::filesystem::rename(partial, out.path, ec);
  if (ec) throw InputError(fmt::format("cannot write {}: {}", out.path, ec.message()));
  return out;
}

}  // namespace vkpose
