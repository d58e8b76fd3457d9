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

#include "analyzer/explain.h"
#include "analyzer/illuminant.h"
#include "analyzer/region_analysis.h"
#include "analyzer/regions.h"

namespace ct::analyzer {

struct Interpretation {
  std::string light_class;   // the class in linear light (the stored values' when they are linear)
  std::string stored_class;  // the class of the values as stored
  std::string process;       // the physical process the class stands for
  std::optional<Vec3> body_colour;   // unit direction of the body (matte) reflection
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
  std::vector<std::string> findings;           // sentences with the numbers above
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
