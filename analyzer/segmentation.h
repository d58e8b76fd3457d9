#pragma once
// Automatic segmentation into colour-consistent regions: mean-shift filtering of rg-chromaticity
// (OpenCV's pyrMeanShiftFiltering, Comaniciu & Meer), then region growing over neighbouring pixels whose
// filtered chromaticities differ by less than a tolerance.
//
// Chromaticity (R, G, B)/(R + G + B) ignores shading, so one matte object stays one region however its
// brightness varies; a highlight moves the chromaticity towards the illuminant's gradually, so growing
// by neighbour differences keeps it with its object, while an edge between two objects is a jump.
// Pixels darker than dark_fraction of the bright end (the 90th percentile of R + G + B, so that an emitter
// in view does not set it) have no reliable chromaticity and stay unassigned, as do segments smaller than
// min_pixels.

#include <vector>

#include "analyzer/image_input.h"
#include "analyzer/regions.h"

namespace ct::analyzer {

struct SegmentationOptions {
  double spatial_radius = 6;      // mean-shift window radius in pixels
  double colour_radius = 0.03;    // mean-shift window radius in chromaticity
  double step_tolerance = 0.012;  // largest chromaticity step between neighbours within a segment
  double dark_fraction = 0.03;
  std::size_t min_pixels = 50;
};

// Segments in order of their first pixel (row-major); named "segment k".
std::vector<Region> segment_regions(const RgbImage& layer, const SegmentationOptions& options);

}  // namespace ct::analyzer
