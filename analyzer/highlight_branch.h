// SPDX-License-Identifier: Apache-2.0
#pragma once
// The colour a highlight adds: the direction of a dichromatic cluster's highlight branch. Each colour of a
// glossy object is c = m_b·body + m_s·light (body reflection plus surface reflection of the light's colour).
// Off the body line, x = m_s·|light⊥| (the distance from the body line) grows with the highlight alone, while
// the position along it, y = c·body = m_b + m_s·(light·body), carries the body's shading as well. Regressing y
// on x over the samples clearly off the body line gives the slope κ = (light·body)/|light⊥| while the shading
// across the highlight does not follow the highlight's strength (its changes are then scatter in y, not a tilt),
// so light ∝ κ·body + e, with e the unit direction of the samples' parts off the body line. A total-least-squares
// line through the highlight's colours instead tilts towards the body colour by as much as the shading spreads
// across the highlight, as it does over a broad one.
//
// Uncertainty: the regression's standard error of κ, the spread of the off-body parts out of their direction,
// and the model's own check — κ measured on the lower and the upper half of the highlight (by x) must agree, as
// they do when the shading is independent of the highlight; half their difference is added as a systematic
// error (shading that does follow the highlight tilts κ on both halves alike, which no check on the cluster alone
// can see).

#include <optional>
#include <vector>

#include "analyzer/line_fit.h"

namespace ct::analyzer {

struct HighlightBranch {
  Vec3 direction = Vec3::Zero();  // unit, the light's colour the highlight adds (components summing to > 0)
  std::size_t samples = 0;        // those clearly off the body line that measured it
  double statistical_deg = 0;     // from the regression and the off-body spread
  double halves_deg = 0;          // between the directions from the lower and upper halves of the highlight
  double uncertainty_deg = 0;     // standard error: statistical and half the halves' difference, in quadrature
};

// `off_body`: indices into points of the samples clearly off the body line. nullopt with fewer than 10, or when
// their distances from the body line do not spread (no highlight grows along them).
std::optional<HighlightBranch> highlight_branch(const std::vector<Vec3>& points, const Line& body,
                                                const std::vector<std::size_t>& off_body);

}  // namespace ct::analyzer
