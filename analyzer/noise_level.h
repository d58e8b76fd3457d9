#pragma once
// The noise level a cluster's extent is judged against.
//
// Sensor noise is independent from pixel to pixel, while real colour structure (shading, highlights,
// interreflection) varies smoothly over the image. So the spread of differences between neighbouring
// pixels of a region, projected on a direction of colour space, measures the noise along that direction
// without being fooled by the structure itself: σ = 1.4826 · median |d·u| / √2 (the MAD of a difference
// of two independent samples). Edges between objects are rare within a region; the median ignores them.

#include <cstdint>
#include <span>
#include <vector>

#include "analyzer/image_input.h"
#include "analyzer/moments.h"
#include "analyzer/regions.h"

namespace ct::analyzer {

// Colour differences of pairs of horizontally and vertically adjacent pixels that both belong to the
// samples, as [pair][channel]; at most `max_pairs`, taken at an even stride over the image.
std::vector<float> neighbour_differences(const RgbImage& image, const RegionSamples& samples, std::size_t max_pairs);

// The noise standard deviation along the unit vector u; never below `floor` (the quantisation noise of
// integer images, step/√12). With no pairs, just the floor.
double noise_sigma(std::span<const float> differences, const Vec3& u, double floor);

}  // namespace ct::analyzer
