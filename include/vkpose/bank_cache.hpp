#pragma once
// Template banks kept between runs: training takes minutes, and the same mesh with the same
// parameters always trains the same bank, so a bank is stored under a key made of both and
// read back instead of trained again.
#include <cstdint>
#include <string>
#include <vector>

#include "vkpose/template_bank.hpp"

namespace vkpose {

/// FNV-1a 64 of what a bank is trained from: the bank format version, the mesh as the bank
/// stores it, the training parameters and every view.
uint64_t trainingKey(const Mesh& mesh, const TrainingParams& params, const std::vector<TrainingView>& views);

/// Where banks are cached: $VKPOSE_CACHE_DIR, else $XDG_CACHE_HOME/vkpose/banks, else
/// $HOME/.cache/vkpose/banks; empty when none of them is set.
std::string defaultBankCacheDir();

struct CachedBank {
  TemplateBank bank;
  bool from_cache = false;  ///< read back rather than trained
  std::string path;         ///< the cache file (empty without a cache folder)
};

/// The bank of `mesh` trained from `views`: read from `cache_dir`/NAME-KEY.vkpb when it is
/// there and sound, else trained and written there (beside and renamed, so a reader in another
/// process never sees half a file). A damaged cache file is trained again and replaced. An
/// empty `cache_dir` trains without caching.
CachedBank loadOrTrainBank(const GpuContext& ctx, const Mesh& mesh, const TrainingParams& params,
                           const std::vector<TrainingView>& views, const std::string& cache_dir,
                           const TrainingProgress& progress = {});

}  // namespace vkpose
