// SPDX-License-Identifier: Apache-2.0
#pragma once
// Spectral lanes: the wavelengths one path carries at once.
//
// In `bands` mode a path carries every band of the plan (up to kMaxLanes at a time), each with its band
// average reflectance and emission — what Cycles computes when bands are multiplexed. In `continuous` mode
// it carries kHeroLanes wavelengths spread evenly over the range from one random offset (hero-wavelength
// sampling, Wilkie et al. 2014), each evaluated exactly, and splats them into the output bands.

#include <Eigen/Core>

namespace ct::rt {

inline constexpr int kMaxLanes = 64;
inline constexpr int kHeroLanes = 4;

// A value per lane, stored inline (no heap allocation on the path-tracing hot path).
using Lanes = Eigen::Array<double, Eigen::Dynamic, 1, 0, kMaxLanes, 1>;

}  // namespace ct::rt
