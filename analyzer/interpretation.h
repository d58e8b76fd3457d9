// SPDX-License-Identifier: Apache-2.0
#pragma once
// What a region's cluster says about how its light was made, in words carrying the region's own numbers: the
// physical process its class stands for (the class in linear light when a curve encoded the values), its body
// colour, the light's colour and the angle between them, where its highlight branch points and how far it
// reaches, what is clipped at which level, how much thicker than its noise it is and what would explain that,
// the γ the file declares, and what is uncertain. For a render with component layers it joins the light-path
// attribution (explain.h) and what bends the cluster (bend_cause.h), which it quotes rather than repeats.

#include <optional>
#include <string>
#include <vector>

#include "analyzer/cluster_shape.h"
#include "analyzer/explain.h"
#include "analyzer/illuminant.h"
#include "analyzer/region_analysis.h"
#include "analyzer/regions.h"

namespace ct::analyzer {

// One sentence of an interpretation and the kind of claim it makes. Each kind has a premise, checked before the
// sentence is written (docs/analyze.md, "Statements and their premises"); where a premise fails, a sentence of
// another kind says what is true instead. The kinds are stable names: tests recompute each premise from
// analysis.json and the image.
struct Statement {
  std::string kind;
  std::string text;
  // The premises the sentence rests on, by name (docs/analyze.md lists them and how each is measured):
  // reaches_black, misses_black, light_highlight, not_light_highlight, within_noise, no_top_clipping,
  // top_clipped, at_black_dim, at_black_bright, on_model_plane, off_model_plane, gamma_measured, gamma_not_measured,
  // thick, flat, light_coloured, nothing_clipped.
  std::vector<std::string> claims;
};

// Where a straight line of colours passes black: its closest distance to black, and that distance seen from the
// line's brightest end as an angle — 0 for a line through black, along which its direction is a colour.
struct BlackReach {
  double miss = 0;           // closest distance to black, in the cluster's units
  double angle_deg = 0;      // atan(miss / (the brightest end's distance along the line))
  double uncertainty_deg = 0;  // the standard error of that angle (the line's rms over √inliers, its tilt included)
  double allowed_deg = 0;    // max(min_line_angle_deg, 2 × uncertainty): within it, the line reaches black
  bool measured = false;     // the uncertainty is within min_line_angle_deg: the line can tell where it passes
  bool reaches = false;      // measured, and within allowed_deg
};
BlackReach black_reach(const Line& line, double min_line_angle_deg);

// How many 4-connected areas of at least 1 % of its pixels a region is (its pixels sorted, as every region's are),
// in one pass over them.
std::size_t separate_areas(const Region& region, int width);

struct Interpretation {
  std::string light_class;   // the class in linear light (the stored values' when they are linear)
  std::string stored_class;  // the class of the values as stored
  std::string process;       // the physical process the class stands for
  std::string process_kind;  // its statement kind (process.*)
  std::vector<std::string> process_claims;  // the premises it rests on (Statement::claims)
  std::string process_rest_kind;  // a clipped cluster's: the kind of what its pixels off the faces are
  std::optional<Vec3> body_colour;   // unit direction of the body (matte) reflection: only of a line that reaches black
  std::optional<BlackReach> body_reach;  // where the body line passes black (none: no line, a single colour)
  std::optional<Vec3> mean_colour;   // the mean colour, unit (stands for the colour where no body colour is quoted)
  std::optional<Vec3> light_colour;  // the chosen illuminant estimate, unit
  std::string light_method;          // which estimate, and whether it is reliable
  std::optional<double> body_light_angle_deg;  // between the body colour and the light's colour
  std::optional<double> light_off_plane_deg;   // how far the light's colour lies off the region's dichromatic plane
  std::optional<Vec3> highlight_direction;     // the highlight branch, unit, pointing away from the body line
  std::optional<double> highlight_light_angle_deg;  // between the highlight branch and the light's colour
  std::optional<double> highlight_reach;  // the highlight's brightest point over the body line's, in length
  double clipped_fraction = 0;            // of the samples, on faces of the cube
  std::vector<std::string> clipped_faces;  // "R high at 255" …
  std::optional<double> thickness_over_noise;  // σ3 over the noise along the third axis
  std::optional<double> mean_light_angle_deg;  // the mean colour's angle from the light's colour
  std::size_t separate_areas = 0;              // 4-connected parts of at least 1 % of the region (segments)
  std::optional<double> declared_gamma, fitted_gamma, fitted_gamma_se;
  std::string curve;                           // the declared curve, described ("linear" when none)
  std::vector<Statement> findings;             // sentences with the numbers above, each of a kind
  std::vector<std::string> uncertain;          // what the numbers cannot tell
};

// The region's cluster in linear light (its linear_light shape when a curve encoded it), read against the
// image's illuminant estimate. `explanation` is the region's light-path attribution (renders with components),
// `width` the image's width (to find the region's separate areas). Pure: the same inputs give the same words.
Interpretation interpret_region(const RegionAnalysis& region, const Region& pixels, int width,
                                const IlluminantAnalysis& illuminant, const ImageEncoding& encoding,
                                const std::optional<Explanation>& explanation, const ShapeCriteria& criteria);

// One paragraph: the process, then the findings, then what is uncertain.
std::string interpretation_text(const Interpretation& i);

}  // namespace ct::analyzer
