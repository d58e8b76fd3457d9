// SPDX-License-Identifier: Apache-2.0
#pragma once
// What bends a cluster (docs/analyze.md, "What bends a cluster"). A cluster is bent when its principal curve
// departs from its chord by more than max_bend_for_straight (the curve model's own test of straightness). Four
// things can bend it, and each is taken away in turn:
//
//   camera curve      the file's response curve           the cluster in linear light
//   mixing at edges   pixel-area integration at edges     the region without its mixed edge pixels
//   highlight lobe    the glossy components               the linear total less glossy_direct, glossy_indirect
//   interreflection   the indirect components             the direct light alone (emission, *_direct; else
//                                                         bounce.0 + bounce.1)
//
// A cause bends the cluster when taking it away leaves the cluster straight (bend <= max_bend_for_straight), and
// adds to its bend when taking it away lowers the bend by more than max_bend_for_straight (a response curve bending
// a highlight's L further); both are named. When no cause does either, the one whose removal lowers the bend most is
// named as the main cause, and the summary says "mostly". The components are the noise-free linear camera signal,
// so the two light-path tests measure the light itself; the other two measure the analysed values.

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "analyzer/cluster_shape.h"
#include "analyzer/image_input.h"
#include "analyzer/regions.h"

namespace ct::analyzer {

inline constexpr const char* kCauseCameraCurve = "camera curve";
inline constexpr const char* kCauseEdgeMixing = "mixing at edges";
inline constexpr const char* kCauseHighlight = "highlight lobe";
inline constexpr const char* kCauseInterreflection = "interreflection";

// One cause taken away: the bend of what is left.
struct BendTest {
  std::string cause;    // one of the four above
  std::string without;  // what was taken away, for a person
  double bend = 0;      // sagitta / chord of what is left
  bool straight = false;  // bend <= max_bend_for_straight
};

struct BendCause {
  double bend = 0;            // of the cluster as analysed
  double reference_bend = 0;  // of the light the component tests start from (the linear total), or the analysed one
  std::vector<BendTest> tests;
  std::vector<std::string> causes;  // those whose removal leaves it straight or lowers it by more than a straight bend; else the main one
  bool straightened = false;         // whether taking one cause away leaves it straight
  std::string summary;               // one line, with the numbers
};

// The bend of a set of colours: the principal curve's sagitta over chord (0 for fewer than 5 colours).
double bend_of(const std::vector<Vec3>& colours);

// nullopt when the cluster is not bent (no principal curve, or its bend <= max_bend_for_straight). `stored` is the
// analysed layer; `linear_light` the region's shape in linear light when a response curve encoded it; `mixed` the
// region's mixed edge pixels (edge_mixing.h; empty when none or not looked for).
std::optional<BendCause> find_bend_cause(const AnalysisImage& input, const RgbImage& stored, const Region& region,
                                         const ClusterShape& shape, const ClusterShape* linear_light,
                                         const std::vector<std::uint32_t>& mixed, const ShapeCriteria& criteria);

}  // namespace ct::analyzer
