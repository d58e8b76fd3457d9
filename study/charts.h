// SPDX-License-Identifier: Apache-2.0
#pragma once
// The study's charts (docs/study.md), PNG drawn with OpenCV and the plotting kit (plot/): error against render
// cost on logarithmic axes, one marker per setting coloured by the knob it changes (a circle for the tracer, a
// square for Cycles), the Pareto front as a staircase through the settings no other beats on both, and a dotted
// line at ΔE00 = 1.
//
//   error_vs_cost.png      mean ΔE00 against CPU seconds
//   p95_vs_cost.png        95th-percentile ΔE00 against CPU seconds
//   systematic_vs_cost.png the systematic rms ΔE00 (bands, bounces, mode, renderer) with its ±2 standard-error
//                          interval as a bar, against CPU seconds
//   structure_vs_cost.png  the largest turn of an object's principal direction (degrees) against CPU seconds;
//                          a setting that changes any object's class is drawn as a cross

#include <filesystem>
#include <vector>

#include <opencv2/core.hpp>

#include "study/study.h"

namespace ct::study {

enum class ChartValue { MeanDe00, P95De00, SystematicRms, DirectionDeg };

// A logarithmic axis over `values` (each at least `floor`): their range padded by a tenth of a decade each side (a
// single value: half a decade), widened to its ticks (plot::log_ticks) where they fall outside, so that at least
// two ticks are on the axis.
struct LogRange {
  double lo, hi;
  std::vector<double> ticks;
};
LogRange log_range(std::vector<double> values, double floor);

// 8-bit BGR.
cv::Mat chart(const StudyResult& result, ChartValue value);

void write_charts(const std::filesystem::path& dir, const StudyResult& result);

}  // namespace ct::study
