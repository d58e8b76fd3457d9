// SPDX-License-Identifier: Apache-2.0
#pragma once
// PNG plots of a region's colour histogram, drawn with OpenCV: the RG, RB and GB projections and an
// oblique 3D view of the RGB cube, with the fitted lines, curve and plane drawn over the points.

#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "analyzer/analysis.h"

namespace ct::analyzer {

enum class PlotColouring {
  Own,        // each point in its own colour
  Density,    // log-density of its histogram cell (the projections show their own 2D densities)
  Component,  // the light-path component that dominates its pixel
};
std::string_view colouring_name(PlotColouring colouring);  // "own", "density", "component"

// Per pixel index into `component_names` (analyzer/explain.h, dominant_component_map); used by Component.
struct ComponentMap {
  std::vector<int> dominant;
  std::vector<std::string> names;
};

// The colour range plots and the report show a region in: the format's cube [0, full scale]³ for integer
// images (its faces are where clipping happens); for float images the region's own range, one for all
// three channels (histogram_spec of its samples), so that a dim object is not lost in a corner of a range
// set by a bright emitter elsewhere in the image.
HistogramSpec display_range(const ImageAnalysis& analysis, const RegionSamples& samples);

// What the plotted values are, short (an axis's unit) and in full (the plot's subtitle, the report): codes or
// values as stored, linear or encoded by a named curve.
struct ValueUnit {
  std::string axis;
  std::string description;
};
ValueUnit value_unit(const ImageAnalysis& analysis);

// An 8-bit BGR image, 2 × 2 panels under a title and a line saying the axes' unit; every axis has tick values
// (plot/ticks.h) and the 3D view is the oblique cube (plot/oblique_cube.h).
cv::Mat plot_region(const RgbImage& layer, const ImageAnalysis& analysis, std::size_t region, PlotColouring colouring,
                    const ComponentMap& components);

// The categorical colour of component k in plots and the report (BGR).
cv::Scalar component_colour(std::size_t k);

}  // namespace ct::analyzer
