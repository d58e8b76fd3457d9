// SPDX-License-Identifier: Apache-2.0
#pragma once
// Several luminaires of different colours lighting one region: the paper's superposed structures. With the
// light-group component layers of a simulated image (light.<group>.R/G/B), each group's share of the region's
// energy and the colour it gives the region are known; when two or more groups each carry a real share and
// their colours differ, the region's cluster is their superposition, whatever shape the sum takes.

#include <optional>
#include <string>
#include <vector>

#include "analyzer/cluster_shape.h"
#include "analyzer/image_input.h"
#include "analyzer/regions.h"

namespace ct::analyzer {

struct LightGroupShare {
  std::string name;             // "light.warm"
  double share = 0;             // of the light groups' summed energy (R + G + B) over the region
  Vec3 colour = Vec3::Zero();   // unit direction of the group's summed R, G, B over the region
};

struct Superposition {
  std::vector<LightGroupShare> groups;  // every light group, largest share first
  double angle_deg = 0;                 // the largest angle between the colours of two groups holding superposed_share
  bool superposed = false;              // at least two groups hold superposed_share and their colours differ by min_line_angle_deg
};

// nullopt without at least two light-group layers.
std::optional<Superposition> find_superposition(const AnalysisImage& input, const Region& region, const ShapeCriteria& criteria);

// Recasts a measured shape as `superposed` when `superposition` says so, adding its tests to the decisions
// and naming the shape the sum has in the reason.
void apply_superposition(ClusterShape& shape, const Superposition& superposition, const ShapeCriteria& criteria);

}  // namespace ct::analyzer
