// SPDX-License-Identifier: Apache-2.0
#pragma once
// Pixel area integration at object edges (the paper's interpolated structures, Figure 4b): a pixel that
// straddles the edge between two objects records a mix of their colours, which lies between their clusters.
// With an id per pixel (object_id, or a label image), an edge pixel of region A next to region B (one of its
// eight neighbours) is mixed when its colour lies on the segment between A's colour at the edge
// (extrapolated from the two pixels behind it) and B's just beyond it.
// When leaving the mixed pixels out changes the region's class, or the rest is a line and the mixed pixels
// make most of the samples off it (a tail towards a neighbour's cluster), the class seen was made by the
// mixing: the region is `mixed`, and its reason names the class of the rest.

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "analyzer/image_input.h"
#include "analyzer/region_analysis.h"
#include "analyzer/regions.h"

namespace ct::analyzer {

struct EdgeMixing {
  std::size_t edge_pixels = 0;          // pixels of the region with an 8-neighbour of another id
  std::vector<std::uint32_t> mixed;     // of those, the mixed ones (indices y·width + x, increasing)
  std::map<std::int32_t, std::size_t> with;  // neighbour id → mixed pixels towards it
};

// `labels` per pixel ([y][x]); `region` holds the pixels of id `label`; `noise` is the colour noise σ the
// comparisons allow for. Colours are compared by direction (shading changes a colour's length, a mix its
// direction): a mixed pixel's direction lies between A's and B's, at least 5 % of the way and more than 3σ/|c|
// from A's, and within 3σ/|c| or 10 %
// of their angle of the plane they span.
EdgeMixing find_edge_mixing(const RgbImage& layer, const std::vector<std::int32_t>& labels, const Region& region,
                            std::int32_t label, double noise);

// Analyses the region without its mixed pixels; when that changes the class, or the mixed pixels are the tail
// off the rest's line (and at least min_mixed_samples pixels are mixed), `analysed` becomes `mixed`. Its
// decisions record the tests either way.
void apply_edge_mixing(RegionAnalysis& analysed, const EdgeMixing& mixing, const RgbImage& layer, const LayerContext& context,
                       const Region& region, const AnalyzeOptions& options, const std::map<std::int32_t, std::string>& names);

}  // namespace ct::analyzer
