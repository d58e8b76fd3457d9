// SPDX-License-Identifier: Apache-2.0
#pragma once
// The illuminant's colour, inferred from the clusters as the dichromatic reflection model allows:
//  - highlight lines: the specular part of a dichromatic surface has the illuminant's colour, so the
//    highlight line of an L or skewed-T points along it (weighted by the line's pixel count);
//  - plane intersection: every dichromatic object's plane through black holds the illuminant's
//    direction, so that direction is the one closest to all the planes (the eigenvector of Σ n nᵀ with
//    the smallest eigenvalue; for two planes, the cross product of their normals);
//  - the colour-constancy literature's statistical methods (analyzer/colour_constancy.h: grey world, white patch,
//    shades of grey, grey edge), each under its own assumption about the world's surfaces: what the physics must
//    beat, and what stands in when the physics finds no evidence.
// Directions are unit RGB vectors in the analysed layer's space, oriented with a positive sum.

#include <optional>
#include <span>
#include <string>
#include <vector>

#include "analyzer/analysis_image.h"
#include "analyzer/iic.h"
#include "analyzer/lights_in_view.h"
#include "analyzer/region_analysis.h"
#include "analyzer/regions.h"

namespace ct::analyzer {

struct IlluminantEstimate {
  std::string method;  // "highlight lines", "dichromatic planes", "grey world"
  Vec3 rgb = Vec3::Zero();
  std::vector<std::string> regions;  // the regions it came from (empty for grey world)
  std::optional<double> error_deg;   // against the known illuminant, when given
  // The standard error of the direction in degrees, were the dichromatic model to hold: from the lines' or
  // planes' fits (their spread about the fit, their extent, their sample counts) and, with several regions,
  // from how far they disagree. None for grey world, which is a guess, not a measurement.
  std::optional<double> uncertainty_deg;
  // A known systematic error its uncertainty leaves out, in words ("" when none is known): a highlight line
  // fitted across a highlight tilts towards its body colour where the shading changes along it.
  std::string systematic;
  // Whether the evidence supports the estimate; when not, why (a person reads it beside the estimate).
  bool reliable = true;
  std::string unreliable_reason;
  // The angle to the camera's as-shot white balance (camera raw files), a reference, not the truth.
  std::optional<double> camera_angle_deg;
};

struct IlluminantAnalysis {
  std::optional<IlluminantEstimate> highlight_lines, planes;
  // Inverse-intensity chromaticity (analyzer/iic.h): the highlights' lines in (1/ΣI, σ), when the regions' pixels
  // were given and a highlight moves a surface's chromaticity.
  std::optional<IlluminantEstimate> iic;
  // The statistical methods in the order of baseline_methods(): grey world first.
  std::vector<IlluminantEstimate> statistical;
  std::optional<Vec3> known;  // as given, normalised
  // The light's colour the camera assumed (the inverse of a raw file's as-shot white-balance multipliers), unit.
  std::optional<Vec3> camera_white;
  // Lights seen directly (analyzer/lights_in_view.h): references, left out of every estimate, and the regions
  // that are mostly one (left out of the dichromatic evidence).
  std::vector<LightInView> lights;
  std::vector<std::string> light_regions;
  std::vector<std::string> notes;  // why an estimate is missing, and regions left out
  std::string choice;              // which estimate best() is, and why
  bool photograph = false;         // IlluminantContext::photograph: which choice and calibration applied

  const IlluminantEstimate& grey_world() const { return statistical.front(); }

  // The estimate to trust: choose(*this, choice_rule()).
  const IlluminantEstimate& best() const;
  // Every estimate made: the physics' first (planes, highlight lines, inverse-intensity chromaticity), then the
  // statistical methods.
  std::vector<const IlluminantEstimate*> all() const;
};

// How the estimate to trust is chosen among those made, on a photograph: a physics estimate (the planes first, then
// the highlight lines, then inverse-intensity chromaticity) when it is reliable and its standard error is at most
// `max_physics_sigma_deg`, else the statistical method `fallback`. On a render made by chromatrace, where the
// dichromatic model holds by construction, the first reliable physics estimate, whatever its standard error (as the
// synthetic renders' tests validate), else `fallback`. Neither value is set by hand: they are those with the least
// mean error on the tuned part of the test set of photographs (tests/data/photos; among values it cannot tell apart,
// the largest physics limit), and leave-one-out over that part judges the rule; the held-out part never tunes it
// (tests/analyzer/test_photographs.cpp, LightColour; the tables in docs/analyze.md). With the physics estimates' priors
// on photographs above 9°, no physics estimate reaches the limit of 8° on the test set: on photographs the choice is,
// today, the fallback.
struct ChoiceRule {
  double max_physics_sigma_deg = 0;
  std::string fallback;
};
const ChoiceRule& choice_rule();
const IlluminantEstimate& choose(const IlluminantAnalysis& analysis, const ChoiceRule& rule);

// A method's error that its own uncertainty leaves out — how far its assumption or model fails on real scenes — as a
// standard error per axis in degrees, fitted on its errors e on the tuned part of the test set of photographs (like
// the choice): the larger of √(ln 10 · mean e² / 4), the σ whose 2σ holds 90 % of a two-dimensional normal error of
// that mean square, and half the errors' 90th percentile, where their tail is heavier than a normal one's. 0 for a method not in the list. The statistical methods carry it
// always (their bootstrap sees nothing of their assumption); the physics estimates only on a photograph
// (IlluminantContext::photograph): on a render the dichromatic model holds, and their fits' errors are the whole.
double method_prior_deg(const std::string& method);

// The largest 2σ an estimate marked reliable may state, in degrees: beyond it the estimate says too little of the
// light to build on, and is marked unreliable with its 2σ.
inline constexpr double kReliableTwoSigmaDeg = 20.0;

// What the estimate knows besides the regions.
struct IlluminantContext {
  std::optional<Vec3> known;  // the light's colour when given (for the errors), any length
  // Clipping levels (+∞ where none is known) and the file's black: a pixel at or past either in any channel lost
  // its colour, and counts in no statistical method.
  std::array<double, 3> high_levels{kNoLevel, kNoLevel, kNoLevel};
  std::array<double, 3> low_levels{-kNoLevel, -kNoLevel, -kNoLevel};
  std::optional<Vec3> camera_white;  // a camera raw's as-shot white balance as a light's colour
  // The regions' pixels, in the order of their analyses (empty: not given). Their segments give inverse-intensity
  // chromaticity its surfaces; those that are mostly a light seen directly are no dichromatic object.
  std::span<const Region> pixels;
  // A photograph rather than a render made by chromatrace (which names its objects or light paths): the physics
  // estimates then carry their priors on real scenes (method_prior_deg).
  bool photograph = false;
  // A response curve that was guessed rather than declared ("" when declared or none): the planes' estimate is
  // then unreliable.
  std::string assumed_curve;
};

// From the regions other than the whole image (which mixes objects) when there are any. The statistical methods
// read `image`, the whole layer in linear light. A highlight line whose bright end lies within 2τ of a clipping
// level is left out: past the level the highlight is cut off, and what remains bends towards the face of the cube,
// not along the light.
IlluminantAnalysis estimate_illuminant(const std::vector<RegionAnalysis>& regions, const RgbImage& image,
                                       const IlluminantContext& context);

// The angle between two colour directions, in degrees.
double angular_error_deg(const Vec3& a, const Vec3& b);

// Plane-intersection direction of planes through black with these normals; nullopt with fewer than two
// planes or when they are all (nearly, within 1°) the same plane.
std::optional<Vec3> intersect_planes(const std::vector<Vec3>& normals);

}  // namespace ct::analyzer
