// SPDX-License-Identifier: Apache-2.0
#pragma once
// The light's colour from highlights in inverse-intensity chromaticity (IIC) space: Tan, Nishino and Ikeuchi
// (2004, "Color constancy through inverse-intensity chromaticity space", JOSA A 21(3)).
//
// Under the dichromatic model a colour is I = m_d·B + m_s·G (B the body colour, G the light's, both scaled to
// a unit component sum). With σ = I / ΣI its chromaticity and Γ = G / ΣG the light's,
//
//     σ_c = p_c · (1 / ΣI) + Γ_c,      p_c = m_d · (B_c − Γ_c),
//
// so where m_d is constant (across a highlight the shading changes slowly while m_s changes fast) the pixels
// of one surface lie on a straight line in the (1/ΣI, σ_c) plane whose intercept at 1/ΣI = 0 is the light's
// chromaticity. Diffuse pixels (m_s = 0) sit at σ = B whatever their brightness: a horizontal line, whose
// intercept is the body colour, not the light's. So only highlight pixels count, and only where the highlight
// moves the chromaticity away from the body colour; a surface whose body colour is the light's gives no line.
//
// The line, written in camera values, is I_c = Γ_c·ΣI + p_c: a straight line in RGB whose direction is Γ. It is
// fitted there, by total least squares (the principal axis of the highlight pixels about their mean), because
// the sensor's noise is the same in each channel of I but not in σ (it grows as 1/ΣI) nor in 1/ΣI, and a
// regression of σ on 1/ΣI with noise in 1/ΣI pulls the intercept towards grey. The paper finds the line by a
// Hough transform; one surface here is one region, given already segmented, so a robust fit per region (with
// one pass that drops pixels far off the line) takes the Hough transform's place, and the paper's histogram of
// intercepts becomes the consensus below.
//
// Across surfaces, the estimate is the intercept with most support: each surface's line votes for the
// intercepts that agree with its own (within settings.consensus_deg, or three times their standard errors when
// that is larger); the intercept with most votes wins (ties: more highlight pixels, then the earlier surface)
// and the estimate is the pixel-weighted mean chromaticity of the surfaces that agree with it. Surfaces lit by
// another light (a second lamp, a window) therefore do not pull the estimate: they are counted in
// `disagreeing`, and the bootstrap below, which resamples the surfaces, switches between the groups as often as
// their sizes allow, so that two groups of similar size give an uncertainty of the order of the angle between
// their lights (two surfaces, one per light: about half that angle).
//
// Uncertainty: a bootstrap of each level of the evidence alone (resampling both at once would count the pixel
// noise twice, since the scatter between surfaces already holds it). Over pixels: each replicate refits every
// surface's line to its highlight pixels drawn with replacement and takes the consensus again. Over surfaces:
// each replicate draws the surfaces' lines with replacement and takes the consensus again. `uncertainty_deg` is
// the larger of the two root-mean-square angles of the replicates to the estimate: a standard error of the
// direction from the pixel noise, or from the scatter between surfaces where that is larger (surfaces lit
// differently, or fitting the model differently). It does not see errors that every surface shares: shading
// that changes across every highlight (m_d not constant) tilts each line towards its body colour, and no
// resampling of the same surfaces can show it. The surface level is coarse with few surfaces (about √((n − 1)/n)
// too small on average, and a draw of 2 to 5 surfaces switches groups in steps) and absent with one.

#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "analyzer/moments.h"

namespace ct::analyzer {

struct IicSurface {            // one region's pixels, linear RGB triplets (n × 3 floats), only usable pixels
  std::span<const float> rgb;  // already excludes clipped and non-finite pixels
};

struct IicSettings {
  // Surfaces with fewer pixels are skipped: the body colour and the noise are measured on the darker half, which
  // must hold enough diffuse pixels for a median to mean something.
  std::size_t min_surface_pixels = 20;
  // The darker part of a surface, by ΣI, taken as its diffuse reference: highlights are the bright part, so the
  // darker half is diffuse but for the weakest highlight pixels, and the median chromaticity ignores those.
  double reference_fraction = 0.5;
  // A pixel is a highlight pixel when its chromaticity lies farther from the body's than this many standard
  // deviations of the reference pixels' chromaticity noise (which scales as 1/ΣI, so the threshold is set per
  // pixel). Four: a pure-noise pixel passes with probability e^(−8) ≈ 3·10⁻⁴ (a two-dimensional normal), too
  // rarely to form a line of min_line_pixels.
  double highlight_sigmas = 4.0;
  // ... and farther than this in any case (chromaticity units, components summing to 1). For noise-free data
  // the noise is 0; this keeps float rounding (10⁻⁷) from counting as a highlight, and is well below any
  // highlight worth fitting (min_chromaticity_change).
  double min_highlight_shift = 1e-3;
  // Fewer highlight pixels than this make no line: a principal axis of 3-D points from fewer is mostly noise,
  // and the trimming pass below needs a median of residuals.
  std::size_t min_line_pixels = 10;
  // One pass drops pixels whose distance from the first line exceeds this many times the robust RMS of the
  // perpendicular distances (stray pixels at a region's border, mixing with its neighbour); Gaussian noise loses
  // about 1 % of its pixels, symmetrically, so the line does not move.
  double trim_sigmas = 3.0;
  // The line must change the chromaticity by at least this much (Euclidean, chromaticity units) across the
  // highlight pixels it was fitted to. A horizontal line (body colour at the light's, or a diffuse surface) has
  // an intercept that is its body colour; a nearly horizontal one has an intercept extrapolated from a change
  // too small to trust. 0.01 is about 1.4° of RGB angle near grey, and ten times min_highlight_shift.
  double min_chromaticity_change = 0.01;
  // Two surfaces' intercepts agree when their angle is at most this (degrees) ...
  double consensus_deg = 2.0;
  // ... or at most this many times their combined standard error (each surface's from a bootstrap over its
  // pixels), when that is larger: noisy highlights must not split one light into several.
  double consensus_sigmas = 3.0;
  // A surface's highlight pixels beyond this many are thinned by an even stride before the line is fitted: the fit and
  // its bootstraps cost time in proportion to the pixels (a 24-megapixel photograph's large segments hold millions),
  // and 5 000 pixels fix a line's direction far below any other error here. The pixel level of the uncertainty is
  // then that of the pixels kept, larger than all of them would give: it errs on the side of caution.
  std::size_t max_line_pixels = 5000;
  // Bootstrap replicates: 200 give the root-mean-square angle to about ±5 % (1/√(2·200)).
  int replicates = 200;
  std::uint64_t seed = 1;  // of the bootstrap's counter-based generator: the same inputs give the same bytes
};

struct IicEstimate {
  Vec3 rgb = Vec3::Zero();        // unit RGB direction of the light, positive sum
  double uncertainty_deg = 0;     // standard error of the direction: the bootstrap above (pixels and surfaces)
  std::size_t surfaces = 0;       // surfaces that gave a highlight line agreeing with the estimate
  std::size_t pixels = 0;         // highlight pixels of those surfaces' lines
  std::size_t disagreeing = 0;    // surfaces that gave a highlight line with another intercept (another light)
};

struct IicResult {
  std::optional<IicEstimate> estimate;
  std::string reason;  // why none, when none
};

IicResult estimate_iic(const std::vector<IicSurface>& surfaces, const IicSettings& settings = {});

}  // namespace ct::analyzer
