// SPDX-License-Identifier: Apache-2.0
#pragma once
// Which light paths built a cluster, from the component layers of a simulated image (the sensor
// simulator's <component>.R/G/B, in the units of linear.R/G/B).
//
// Components come in families that each sum to the total: path types (emission, diffuse_direct,
// diffuse_indirect, glossy_direct, glossy_indirect, transmission_direct, transmission_indirect), light groups
// (light.<group>) and bounces (bounce.<k>, exactly k scattering events). For a region this gives each
// component's share of the energy (R + G + B summed over the region), the share of pixels each component
// dominates, the direct / indirect and diffuse / glossy splits, and how much of the cluster's spread off
// the structure of the direct light (the dichromatic plane, or the body line of a matte object) the
// indirect components account for: the paper's off-plane thickening.

#include <optional>
#include <string>
#include <vector>

#include "analyzer/image_input.h"
#include "analyzer/moments.h"
#include "analyzer/regions.h"
#include "core/spectral_channel_name.h"

namespace ct::analyzer {

// Families are core's (core/spectral_channel_name.h: component_family, family_name).
// Whether a component carries direct light (emission, *_direct, bounce.0, bounce.1) or indirect light
// (*_indirect, bounce.k for k >= 2); nullopt for lights and others.
std::optional<bool> is_direct(const std::string& component);

struct ComponentShare {
  std::string name;
  double energy_share = 0;     // of the region's total energy
  double dominant_pixels = 0;  // share of the region's pixels where this component is the largest of its family
};

struct FamilyShares {
  ComponentFamily family = ComponentFamily::PathType;
  std::vector<ComponentShare> components;
};

struct OffStructure {
  std::string structure;     // "dichromatic plane" or "body line": what the direct light forms
  Vec3 direction = Vec3::Zero();  // the plane's normal, or the line's direction
  double rms_total = 0;      // rms distance of the total from the direct light's structure
  double rms_direct = 0;     // … of the direct light alone (≈ 0 for a dichromatic object)
  double indirect_share = 0;  // 1 − rms_direct² / rms_total²: share of the spread the indirect light explains
};

struct Explanation {
  std::vector<FamilyShares> families;  // those the file has
  std::optional<double> direct_share, indirect_share;  // from path types (else bounces)
  std::optional<double> diffuse_share, glossy_share;   // from path types
  std::optional<OffStructure> off_structure;
  std::vector<std::string> notes;
};

struct ClusterShape;

// The image noise across the direct light's structure, from the cluster's noise along its principal axes: off its
// principal plane (σ3's noise) for a dichromatic plane, off its principal line (σ2's and σ3's) for a body line.
double noise_across(const OffStructure& off, const ClusterShape& shape);

// Interreflection thickens the cluster when the indirect light makes at least half of its spread off the direct
// light's line or plane, and that spread is more than noise_factor × the noise across it (the paper's thickening).
inline constexpr double kThickeningIndirectShare = 0.5;
bool thickened_by_interreflection(const Explanation& explanation, const ClusterShape& shape);

// nullopt when the file has no component layers.
std::optional<Explanation> explain_region(const AnalysisImage& input, const Region& region);

// Per pixel, the index (into input.components) of the largest component (by R + G + B) of the first family
// the file has among path types, light groups, bounces; −1 where all are zero or not finite. Empty without
// components.
std::vector<int> dominant_component_map(const AnalysisImage& input);

}  // namespace ct::analyzer
