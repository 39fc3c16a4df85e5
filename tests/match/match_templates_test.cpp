// The templates stage 2 runs for a detector's banks (match/match_templates.hpp): the bank
// templates, the colour-alone copies of small parts' templates where the sensor loses them,
// and the copies' matches counted as the bank templates'.
#include <gtest/gtest.h>

#include "match/match_templates.hpp"

namespace vkpose {
namespace {

TemplateFeature feature(int x, Modality modality) { return {x, 2, static_cast<uint8_t>(x % 8), modality}; }

/// A template of two levels with `colour` colour features and `depth` depth features on each.
BankTemplate bankTemplate(int colour, int depth, float distance) {
  BankTemplate t;
  t.distance = distance;
  t.anchor_x = 20.f;
  t.anchor_y = 10.f;
  for (int level = 0; level < 2; ++level) {
    TemplateLevel l;
    l.width = 40 >> level;
    l.height = 20 >> level;
    for (int i = 0; i < colour; ++i) l.features.push_back(feature(i, Modality::ColourGradient));
    for (int i = 0; i < depth; ++i) l.features.push_back(feature(i + 10, Modality::DepthNormal));
    t.linemod.levels.push_back(l);
  }
  return t;
}

TemplateBank bank(const std::string& name, float diameter) {
  TemplateBank b;
  b.object = name;
  b.diameter = diameter;
  b.params.views.radii = {0.3f, 0.5f, 0.05f};
  b.templates = {bankTemplate(5, 4, 0.3f), bankTemplate(6, 0, 0.4f), bankTemplate(3, 3, 0.5f)};
  return b;
}

SensorParams closeRange() { return sensorProfile("close-range"); }

TEST(MatchTemplates, SmallPartsAreAlsoMatchedOnColourAloneWhereTheSensorLosesThem) {
  const std::vector<TemplateBank> banks = {bank("key", 0.17f), bank("nozzle", 0.06f)};
  ASSERT_TRUE(closeRange().small_parts_unreliable);
  const match::MatchTemplates t = match::matchTemplates(banks, MatchParams{}, closeRange());
  ASSERT_EQ(t.origins.bank_templates, 6u);
  // The nozzle's first and last templates have depth features: each gets a copy; its second
  // is colour alone already. The 17 cm key gets none.
  ASSERT_EQ(t.templates.size(), 8u);
  ASSERT_EQ(t.gates.size(), 8u);
  ASSERT_EQ(t.origins.copy_of, (std::vector<int>{3, 5}));
  for (std::size_t i = 0; i < 6; ++i) EXPECT_EQ(t.templates[i], banks[i / 3].templates[i % 3].linemod) << i;
  for (const std::size_t copy : {6u, 7u}) {
    const LinemodTemplate& own = t.templates[static_cast<std::size_t>(t.origins.copy_of[copy - 6])];
    const LinemodTemplate& alone = t.templates[copy];
    ASSERT_EQ(alone.levels.size(), own.levels.size());
    for (std::size_t l = 0; l < own.levels.size(); ++l) {
      EXPECT_EQ(alone.levels[l].width, own.levels[l].width);
      EXPECT_EQ(alone.levels[l].height, own.levels[l].height);
      std::vector<TemplateFeature> colour;
      for (const TemplateFeature& f : own.levels[l].features)
        if (f.modality == Modality::ColourGradient) colour.push_back(f);
      EXPECT_EQ(alone.levels[l].features, colour) << "copy " << copy << " level " << l;
    }
    // The depth gate is the bank template's: the same distance and anchor.
    const auto& g = t.gates[copy];
    const auto& own_gate = t.gates[static_cast<std::size_t>(t.origins.copy_of[copy - 6])];
    EXPECT_EQ(g.z_lo_mm, own_gate.z_lo_mm);
    EXPECT_EQ(g.z_hi_mm, own_gate.z_hi_mm);
    EXPECT_EQ(g.anchor_dc, own_gate.anchor_dc);
    EXPECT_EQ(g.band, own_gate.band);
  }
  // Other sensors, the parameter off, or banks without depth: the bank templates alone.
  EXPECT_EQ(match::matchTemplates(banks, MatchParams{}, SensorParams{}).templates.size(), 6u);
  EXPECT_EQ(match::matchTemplates(banks, MatchParams{}, sensorProfile("realsense-d435")).templates.size(), 6u);
  MatchParams off;
  off.small_part_colour_alone = false;
  EXPECT_EQ(match::matchTemplates(banks, off, closeRange()).templates.size(), 6u);
  std::vector<TemplateBank> colour_banks = banks;
  colour_banks[1].params.features.use_depth = false;
  EXPECT_EQ(match::matchTemplates(colour_banks, MatchParams{}, closeRange()).templates.size(), 6u);
}

TEST(MatchTemplates, ACopysMatchesCountAsItsBankTemplatesWhereItsOwnDidNotMatch) {
  const std::vector<TemplateBank> banks = {bank("key", 0.17f), bank("nozzle", 0.06f)};
  const match::MatchTemplates t = match::matchTemplates(banks, MatchParams{}, closeRange());
  auto m = [](int id, int x, int y, float similarity) { return Match{id, x, y, similarity, static_cast<int>(similarity)}; };
  std::vector<Match> matches = {
      m(3, 10, 10, 84.f),  // bank template 3's own
      m(6, 10, 10, 97.f),  // its copy at the same place: the own match stands
      m(6, 30, 10, 92.f),  // its copy where the own missed: bank template 3 there
      m(7, -4, 5, 88.f),   // bank template 5's copy
      m(7, -4, 5, 90.f),   // a repeat at the same place: the better one
      m(0, 50, 50, 81.f),  // the key's
  };
  match::asBankTemplateMatches(matches, t.origins);
  const std::vector<Match> expected = {m(3, 30, 10, 92.f), m(5, -4, 5, 90.f), m(3, 10, 10, 84.f), m(0, 50, 50, 81.f)};
  EXPECT_EQ(matches, expected);
  // Without copies the matches are left as they are.
  const match::MatchTemplates plain = match::matchTemplates(banks, MatchParams{}, SensorParams{});
  std::vector<Match> same = {m(3, 10, 10, 84.f), m(0, 1, 1, 99.f)};
  match::asBankTemplateMatches(same, plain.origins);
  EXPECT_EQ(same, (std::vector<Match>{m(3, 10, 10, 84.f), m(0, 1, 1, 99.f)}));
}

TEST(MatchTemplates, ColourFeaturesAloneNeedColourOnEveryLevel) {
  const BankTemplate both = bankTemplate(2, 3, 0.4f);
  const auto alone = match::colourFeaturesAlone(both.linemod);
  ASSERT_TRUE(alone);
  for (const TemplateLevel& l : alone->levels) {
    EXPECT_EQ(l.features.size(), 2u);
    for (const TemplateFeature& f : l.features) EXPECT_EQ(f.modality, Modality::ColourGradient);
  }
  BankTemplate depth_on_coarse = both;
  std::erase_if(depth_on_coarse.linemod.levels[1].features,
                [](const TemplateFeature& f) { return f.modality == Modality::ColourGradient; });
  EXPECT_FALSE(match::colourFeaturesAlone(depth_on_coarse.linemod));
}

}  // namespace
}  // namespace vkpose
