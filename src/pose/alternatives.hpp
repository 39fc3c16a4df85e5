#pragma once
// Stage 8, render and compare (docs/pipeline.md, stage 8, near-symmetries and look-alikes): a
// pose that passed the collision test is rendered beside the poses its object could be
// mistaken for, and each is compared with the scene's colour and depth (appearance.hpp). A
// clear winner other than ICP's pose is refined from there and verified again.
#include <cstddef>
#include <utility>
#include <vector>

#include "pose/candidate.hpp"
#include "vkpose/config.hpp"
#include "vkpose/detection.hpp"

namespace vkpose {

/// Of a pose (alternatives[0]) and its alternatives, the one kept: the pose stays unless the
/// best alternative scores `margin` higher. Also by how much the kept one beat the best other.
std::pair<std::size_t, float> chooseAlternative(const std::vector<SymmetryAlternative>& alternatives, float margin);

/// The object's near-symmetric turns (bank.near_symmetries). Where its colours vary
/// (PoseObject::colourful) each turn is rendered and compared, and one that wins by
/// VerifyParams::symmetry_margin replaces the pose (a fine ICP fit from there, then verified
/// again); where they do not, the turns are listed and the pose reported ambiguous. A coloured
/// mesh's pose is also compared alone: its colour agreement is a test of its own. Candidates
/// that did not pass the collision test, twins and hopeless ones are left alone.
void resolveNearSymmetries(PoseCandidate& candidate, const PoseObject& object, const PoseFrame& frame,
                           const DetectorParams& params);

/// Look-alike half-turns (a carton end for end, a jug flank for flank): the templates look
/// alike, so stage 6 may settle on either, and the turn is a centimetre off, so ICP cannot
/// walk from one to the other. The pose is turned by each of PoseObject::look_alike_turns,
/// refit from there (the refits on `params.threads` threads), and all are rendered and
/// compared: colour where it counts, and the depth residual over the whole mask. A winner
/// by symmetry_margin replaces the pose and is verified again.
void resolveLookAlikes(PoseCandidate& candidate, const PoseObject& object, const PoseFrame& frame,
                       const DetectorParams& params);

}  // namespace vkpose
