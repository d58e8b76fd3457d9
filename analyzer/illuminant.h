// SPDX-License-Identifier: Apache-2.0
#pragma once
// The illuminant's colour, inferred from the clusters as the dichromatic reflection model allows:
//  - highlight lines: the specular part of a dichromatic surface has the illuminant's colour, so the
//    highlight line of an L or skewed-T points along it (weighted by the line's pixel count);
//  - plane intersection: every dichromatic object's plane through black holds the illuminant's
//    direction, so that direction is the one closest to all the planes (the eigenvector of Σ n nᵀ with
//    the smallest eigenvalue; for two planes, the cross product of their normals);
//  - grey world, beside them for comparison: the image's mean colour.
// Directions are unit RGB vectors in the analysed layer's space, oriented with a positive sum.

#include <optional>
#include <span>
#include <string>
#include <vector>

#include "analyzer/region_analysis.h"

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
  IlluminantEstimate grey_world;
  std::optional<Vec3> known;  // as given, normalised
  // The light's colour the camera assumed (the inverse of a raw file's as-shot white-balance multipliers), unit.
  std::optional<Vec3> camera_white;
  std::vector<std::string> notes;  // why an estimate is missing, and regions left out
  std::string choice;              // which estimate best() is, and why

  // The estimate to trust most: the planes' intersection when reliable, else the highlight lines when reliable,
  // else grey world (a guess, never reliable). The planes come first although their standard error is often the
  // larger: it looks conservative — on the analyzer's synthetic component render and on StillLife with the bagel
  // (two images, not a sweep) their error is a tenth and a half of it, where the highlight branches' errors are
  // about one of theirs — and the lines may carry a
  // systematic tilt (`systematic`). Choosing by standard error instead puts a synthetic render's light 8.4° off
  // rather than 2.0° (tests/analyzer/test_analyze_command.cpp).
  const IlluminantEstimate& best() const {
    if (planes && planes->reliable) return *planes;
    if (highlight_lines && highlight_lines->reliable) return *highlight_lines;
    return grey_world;
  }
};

// From the regions other than the whole image (which mixes objects) when there are any. The grey world
// averages `rgb`, the whole layer's finite pixels. A highlight line whose bright end lies within 2τ of a
// clipping level (`high_levels`, +∞ where none is known) is left out: past the level the highlight is cut off,
// and what remains bends towards the face of the cube, not along the light. `assumed_curve` names a response curve
// that was guessed rather than declared ("" when declared or none): the planes' estimate is then unreliable.
IlluminantAnalysis estimate_illuminant(const std::vector<RegionAnalysis>& regions, std::span<const float> rgb,
                                       const std::optional<Vec3>& known,
                                       const std::array<double, 3>& high_levels = {kNoLevel, kNoLevel, kNoLevel},
                                       const std::optional<Vec3>& camera_white = std::nullopt,
                                       const std::string& assumed_curve = "");

// The angle between two colour directions, in degrees.
double angular_error_deg(const Vec3& a, const Vec3& b);

// Plane-intersection direction of planes through black with these normals; nullopt with fewer than two
// planes or when they are all (nearly, within 1°) the same plane.
std::optional<Vec3> intersect_planes(const std::vector<Vec3>& normals);

}  // namespace ct::analyzer
