// The templates stage 2 runs for a detector's banks (match/match_templates.hpp).
#include "match/match_templates.hpp"

#include <algorithm>
#include <tuple>

namespace vkpose::match {

std::optional<LinemodTemplate> colourFeaturesAlone(const LinemodTemplate& t) {
  LinemodTemplate c = t;
  for (TemplateLevel& level : c.levels) {
    std::erase_if(level.features, [](const TemplateFeature& f) { return f.modality != Modality::ColourGradient; });
    if (level.features.empty()) return std::nullopt;
  }
  return c;
}

namespace {
bool hasDepthFeatures(const LinemodTemplate& t) {
  return std::any_of(t.levels.begin(), t.levels.end(), [](const TemplateLevel& level) {
    return std::any_of(level.features.begin(), level.features.end(),
                       [](const TemplateFeature& f) { return f.modality == Modality::DepthNormal; });
  });
}
}  // namespace

MatchTemplates matchTemplates(const std::vector<TemplateBank>& banks, const MatchParams& params,
                              const SensorParams& sensor) {
  MatchTemplates out;
  out.gates = templateDepthGates(banks);
  for (const TemplateBank& bank : banks)
    for (const BankTemplate& t : bank.templates) out.templates.push_back(t.linemod);
  out.origins.bank_templates = out.templates.size();
  if (!params.small_part_colour_alone || !sensor.small_parts_unreliable) return out;
  std::size_t first = 0;  // the bank's first template
  for (const TemplateBank& bank : banks) {
    const bool both = bank.params.features.use_colour && bank.params.features.use_depth;
    if (both && isSmallPart(bank.diameter))
      for (std::size_t i = first; i < first + bank.templates.size(); ++i) {
        if (!hasDepthFeatures(out.templates[i])) continue;  // colour alone already
        std::optional<LinemodTemplate> alone = colourFeaturesAlone(out.templates[i]);
        if (!alone) continue;
        out.templates.push_back(std::move(*alone));
        out.gates.push_back(out.gates[i]);
        out.origins.copy_of.push_back(static_cast<int>(i));
      }
    first += bank.templates.size();
  }
  return out;
}

void asBankTemplateMatches(std::vector<Match>& matches, const TemplateOrigins& origins) {
  if (origins.copy_of.empty()) return;  // nothing but bank templates
  struct Tagged {
    Match match;
    bool copy;  // of a colour-alone copy
  };
  std::vector<Tagged> tagged;
  tagged.reserve(matches.size());
  for (Match m : matches) {
    const std::size_t id = static_cast<std::size_t>(m.template_id);
    const bool copy = id >= origins.bank_templates;
    if (copy) m.template_id = origins.copy_of[id - origins.bank_templates];
    tagged.push_back({m, copy});
  }
  // Per bank template and position: its own match first, then the best similarity.
  std::sort(tagged.begin(), tagged.end(), [](const Tagged& a, const Tagged& b) {
    return std::tuple(a.match.template_id, a.match.y, a.match.x, a.copy, b.match.similarity) <
           std::tuple(b.match.template_id, b.match.y, b.match.x, b.copy, a.match.similarity);
  });
  matches.clear();
  for (const Tagged& t : tagged)
    if (matches.empty() || matches.back().template_id != t.match.template_id || matches.back().y != t.match.y ||
        matches.back().x != t.match.x)
      matches.push_back(t.match);
  sortMatches(matches);
}

}  // namespace vkpose::match
