#pragma once
// The templates stage 2 runs for a detector's banks: every bank template, and for parts under
// 10 cm each template's colour features again as a template of their own (colour alone).
// A thin or shiny part that a close-range stereo sensor barely sees (a nozzle lying on the
// floor of a bin: its depth merged into the floor's, holes where its metal faces the camera)
// misses the match threshold on colour and depth together, though its outline matches at
// 95-100 % alone (docs/pipeline.md, stage 2). Their matches count as the bank template's, so
// stages 3-8 are the same.
#include <cstddef>
#include <optional>
#include <vector>

#include "match/depth_gate.hpp"
#include "match/matcher.hpp"
#include "vkpose/bank.hpp"
#include "vkpose/config.hpp"

namespace vkpose::match {

/// A template's colour features alone, every level: none when a level would have none.
std::optional<LinemodTemplate> colourFeaturesAlone(const LinemodTemplate& t);

/// Which bank template each of the matcher's templates matches for: the first `bank_templates`
/// are the bank templates themselves (in concatenateTemplates' order), then the copies.
struct TemplateOrigins {
  std::size_t bank_templates = 0;
  std::vector<int> copy_of;  ///< per copy, the index of the bank template it was made from
};

struct MatchTemplates {
  std::vector<LinemodTemplate> templates;
  std::vector<TemplateDepthGate> gates;  ///< one per template (the bank template's)
  TemplateOrigins origins;
};

/// The bank templates (and depth gates) and, with MatchParams::small_part_colour_alone and a
/// sensor whose depth of small parts is unreliable (SensorParams::small_parts_unreliable), for
/// every bank of a part under 10 cm trained with both modalities, the colour features alone of
/// each template that has depth features too.
MatchTemplates matchTemplates(const std::vector<TemplateBank>& banks, const MatchParams& params,
                              const SensorParams& sensor);

/// The matches of the matcher's templates as the bank templates' (Match::template_id becomes the bank
/// template's index), best first as sortMatches leaves them. Where a bank template and its
/// colour-alone copy matched at one position, the bank template's own match stands: its
/// similarity counts both modalities, and colour alone only adds the positions it missed.
void asBankTemplateMatches(std::vector<Match>& matches, const TemplateOrigins& origins);

}  // namespace vkpose::match
