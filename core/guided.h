// SPDX-License-Identifier: Apache-2.0
#pragma once
// Guided reconstruction of bands rendered with few samples, from bands of the same image rendered with many
// (docs/plan.md, "Guided band groups").
//
// A band-multiplexed Cycles render makes three bands per render, so a spectral image of 6 or 9 bands costs
// 2 or 3 renders. Within one object and one light-path component the shape of the light (shading, shadows,
// highlights) is nearly the same in every band; what changes from band to band is mostly a factor: the
// object's reflectance and the light's spectrum. So the later groups can be rendered with few samples and
// reconstructed as the guide (the sum of the full-sample bands) times a local ratio,
//
//     t̂(p) = g(p) · Σ_q t(q) / Σ_q g(q),   q in the (2r+1)² window around p on the same object,
//
// the ratio estimator of survey sampling. Its noise is the guide's plus the ratio's, which averages the
// few-sample band over the window; its bias is where the ratio is not constant over the window: a shadow
// cast by one of two lights of different spectra, a coloured interreflection's edge, a texture whose colours
// the guide does not tell apart.
//
// Where it cannot work it is not tried, and the pixel keeps its few-sample values: on an object's edge (a pixel
// whose eight neighbours are not all of its object mixes two objects' ratios, and Cycles' light and colour
// passes, each averaged over the pixel's samples, multiply there to a value that depends on the samples); where
// the window's guide is dark, or its light lies in fewer than 16 pixels' worth (a small highlight, whose ratio
// would be as noisy as those pixels).
//
// Each reconstruction is tested before it is kept. The residual of the few-sample band against it,
// e(p) = t(p) − t̂(p), is noise of mean zero where the ratio is constant over the window. Over each object,
// and over each 8 × 8 square of it, the mean residual is compared with its standard error, the noise's
// variance taken from the differences of neighbouring residuals (Rice's estimator: a bias that changes
// slowly from pixel to pixel cancels in them, and the noise may differ from one part of an object to
// another). The threshold on |z| is Bonferroni's over all the squares and objects, for a chance of a false
// refusal of `false_refusal` per layer and band. A reconstruction that moves the structure of a light-path
// component more than its noise shows as a mean residual many standard errors from zero, and is refused:
// that object keeps its few-sample values in that layer and band, and the report names it.
//
// What the test cannot see: a structure finer than its squares whose sign changes from pixel to pixel (a
// texture the guide's colours do not show, the shadows of a fine grating) looks to it like noise, since the
// noise's variance is itself taken from neighbouring pixels. Hence the colour factors below, and no layer
// without one reconstructed unless the caller knows better. And its power is the few-sample render's noise: a
// bias is found when it stands out of that noise over a square or an object, not of the full-sample render's.
//
// The total is not reconstructed on its own when the components include a family that adds up to it (the
// path types, else the light groups, else the bounces): a total reconstructed by its own ratio would mix
// components whose ratios differ (a white highlight on a yellow body) and be biased where their mixture
// changes. It becomes the sum of that family's members; the only member of a further family (one light
// group) is the total and is set to it; and the residual of each further family is spread over its members
// in proportion to their magnitudes, so the file keeps the exact sums `chromatrace info --check` verifies.

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace ct {

// A spectral image held whole: the total and its components, each [y][x][band].
//
// A component that is light × colour (Cycles' Diffuse Direct × Diffuse Color: the light reaching a surface and
// the surface's albedo, which a texture varies from pixel to pixel) may be given as its two factors: the light
// in `layers` and the colour in `colours`. Only the light is then reconstructed, its guide being the light of
// the guide bands: smooth where the texture is not, so that a texture the guide's colours cannot tell apart
// does not bias it; the colour, an albedo, is nearly free of noise at few samples. reconstruct_guided leaves
// the product in `layers`.
struct GuidedImage {
  int width = 0, height = 0;
  std::size_t bands = 0;
  std::vector<std::string> components;      // the layers after the total, by name
  std::vector<std::vector<float>> layers;   // total, then components
  std::vector<std::int32_t> object_ids;     // [y][x]; empty: the whole image is one object
  std::vector<std::vector<float>> colours;  // empty, or one per layer: empty, or the colour factor, [y][x][band]
};

struct GuidedOptions {
  std::vector<std::size_t> guide_bands;   // rendered with the full samples
  std::vector<std::size_t> guided_bands;  // rendered with few samples, reconstructed
  int radius = 4;                         // the window is (2·radius + 1)² pixels
  double false_refusal = 1e-4;            // chance of refusing a good reconstruction, per layer and band
  // Whether a layer without a colour factor is reconstructed. A texture the guide cannot see varies the ratio
  // from pixel to pixel like noise, so the test cannot tell it from noise, and the window would average it
  // away; only a caller who knows the image has no such texture (a scene of plain materials) should say yes.
  bool unfactored_layers = false;
  int threads = 0;
};

// What the test found for one object in one layer and band.
struct GuidedVerdict {
  std::size_t layer = 0;  // 0 the total, else components[layer − 1]
  std::size_t band = 0;
  std::int32_t object = 0;
  bool refused = false;
  double worst_z = 0;     // the largest |z| over the object and its squares
  double threshold = 0;   // the |z| above which it is refused
  std::size_t pixels = 0;
};

struct GuidedReport {
  std::vector<GuidedVerdict> verdicts;  // by layer, band, object
  std::size_t refused() const;
};

// Reconstructs options.guided_bands of every layer with a colour factor (and, with unfactored_layers, of every
// other) in place, object by object, and reconciles the families.
// Throws std::invalid_argument for options that do not fit the image (a band out of range, in both lists,
// or no guide band).
GuidedReport reconstruct_guided(GuidedImage& image, const GuidedOptions& options);

// The |z| that a standard normal exceeds with probability p (two-sided): 1.96 for 0.05, 3.89 for 1e-4.
double two_sided_normal_threshold(double p);

}  // namespace ct
