#include <string>

#include "vkpose/bank.hpp"
#include "vkpose/error.hpp"

namespace vkpose {

void validateTemplates(const std::vector<LinemodTemplate>& templates, const FeatureParams& params) {
  for (std::size_t i = 0; i < templates.size(); ++i) {
    const auto& t = templates[i];
    const std::string name = "template " + std::to_string(i);
    if (t.levels.size() != params.T.size())
      throw InputError(name + " has " + std::to_string(t.levels.size()) + " pyramid levels, the matcher " +
                       std::to_string(params.T.size()));
    for (std::size_t l = 0; l < t.levels.size(); ++l) {
      const auto& level = t.levels[l];
      if (level.features.empty()) throw InputError(name + " has no features at level " + std::to_string(l));
      if (level.features.size() > 8192)
        throw InputError(name + " has more than 8192 features at level " + std::to_string(l));
      if (level.width < 0 || level.height < 0 || level.width > 4096 || level.height > 4096)
        throw InputError(name + " has a nonsense size at level " + std::to_string(l));
      for (const auto& f : level.features) {
        if (f.x < 0 || f.y < 0 || f.x > 4096 || f.y > 4096 || f.bin > 7)
          throw InputError(name + " has a feature outside its template at level " + std::to_string(l));
        if ((f.modality == Modality::ColourGradient && !params.use_colour) ||
            (f.modality == Modality::DepthNormal && !params.use_depth))
          throw InputError(name + " uses a modality that is switched off");
      }
    }
  }
}

}  // namespace vkpose
