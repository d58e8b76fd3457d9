// SPDX-License-Identifier: Apache-2.0
#pragma once
// The shape of a colour cluster: its moments judged against the noise level, robust line and plane fits
// in the dichromatic model (body line, highlight line, where the highlight leaves the body line), the
// principal curve, a gamma diagnosis, clipping, and from all these one class.
//
// Each class is decided by numbered tests on those numbers, in this order (docs/analyze.md, "Classes",
// states the same with the thresholds of ShapeCriteria):
//   none      fewer than min_samples valid samples, or all black
//   clipped   at least clipped_fraction of the samples on faces of the RGB cube — unless every face is at black
//             and they hold less than black_faces_fraction: then the class of the samples off the faces
//   point     no σk above noise_factor × the noise along its axis
//   linear    σ2 not significant, or the body line holds body_only_fraction of the samples
//   L         body + highlight lines leave a small residual (two_line_residual), meet at an angle, the highlight leaving the body
//   skewed-T  line at its bright end (L) or part-way along it (skewed-T) …
//   fork      … or near its dark end (t_junction): two lines diverging from near black
//   gamma     a quadratic principal curve explains the off-line spread, and a power curve straightens it
//   curved    … and no power curve straightens it (the "banana")
//   thickened σ3 significant but at most thickened_ratio of σ2: a plane with spread off it
//   volume    σ3 larger than that
//   thickened-line  σ2 at most thick_line_ratio × σ1, the samples off the body line all along it
//   P         the body line holds p_body_fraction, the rest fills an area on one side of it
//   planar    any other cluster in a plane
// where σk = √(eigenvalue k) of the covariance, and σk is significant when it exceeds both
// noise_factor × the noise σ along axis k and relative_floor × σ1.

#include <cstdint>
#include <limits>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "analyzer/clipping.h"
#include "core/structures.h"
#include "analyzer/gamma_fit.h"
#include "analyzer/highlight_branch.h"
#include "analyzer/line_fit.h"
#include "analyzer/moments.h"
#include "analyzer/noise_level.h"
#include "analyzer/principal_curve.h"

namespace ct::analyzer {

// The classes are the project's one vocabulary of structures (core/structures.h).
using ShapeClass = Structure;
inline std::string_view class_name(ShapeClass shape) { return structure_word(shape); }

struct ShapeCriteria {
  std::size_t min_samples = 10;
  std::size_t max_points = 50000;  // samples the fits use: an even stride over larger clusters
  double noise_factor = 3;
  double relative_floor = 0.01;
  double clipped_fraction = 0.02;
  // Faces at black (channels at the file's lowest value) cut off the dim, saturated end of the body line, not the highlight
  // the classes are read from: while they hold less than this share, the cluster is what its samples off the faces
  // are, and its clipping a finding. (Any face at the top cuts the highlight: clipped from clipped_fraction on.)
  double black_faces_fraction = 0.5;
  double body_only_fraction = 0.98;
  double two_line_residual = 0.3;  // the points' rms distance from the nearer line, as a share of σ2
  std::size_t min_highlight_samples = 5;  // a line: two samples fix it, three more confirm it …
  double min_highlight_fraction = 0;      // (off: a small object's highlight holds few of its pixels)
  double highlight_length = 3;            // … and it is at least this many tolerances τ long
  double min_line_angle_deg = 3;
  double highlight_end = 0.15;      // the junction lies within this share of the highlight line's end
  double l_junction = 0.85;         // junction at or beyond this position along the body line: L
  double t_junction = 0.1;          // between this and l_junction: skewed-T
  double max_bend_for_straight = 0.02;  // bend (sagitta / chord) above this is curved
  double curve_residual = 0.15;     // the curve's rms within this share of the straight line's rms (or 2 × noise)
  double gamma_straightening = 0.02;  // linearised off-line variance within this share of the stored one
  double min_gamma_departure = 0.05;  // |γ − 1| at least this for a gamma diagnosis
  double thickened_ratio = 0.35;
  double thick_line_ratio = 0.06;     // σ2 / σ1 at most this …
  double thick_line_coverage = 0.5;  // … and the samples off the body line along this share of it: a thickened line
  double p_body_fraction = 0.3;
  double p_one_side = 0.95;
  double p_area_ratio = 0.15;
  double superposed_share = 0.1;
  std::size_t min_mixed_samples = 5;  // mixed edge pixels that can make a structure (as min_highlight_samples)  // two light groups each carrying this share of a region's light: superposed
};

// A plane n·x = offset with the rms distance of the samples from it.
struct Plane {
  Vec3 normal = Vec3::UnitZ();
  double offset = 0;
  double rms = 0;
};

// One test of the decision, as it was made: value against threshold.
struct Decision {
  std::string test;
  double value = 0;
  double threshold = 0;
  bool passed = false;
};

struct TwoLines {
  Line body, highlight;           // highlight.direction points away from the junction
  Vec3 junction = Vec3::Zero();   // where the highlight leaves the body line
  double junction_on_body = 0;    // 0 at the body line's dark end, 1 at its bright end
  double junction_on_highlight = 0;  // 0 or 1 at an end of the highlight line
  double gap = 0;                 // distance between the two lines at the junction
  double angle_deg = 0;
  double body_fraction = 0, highlight_fraction = 0;
};

struct ClusterShape {
  ShapeClass shape = ShapeClass::None;
  std::string reason;  // one sentence: why this class, or why no shape was measured
  std::vector<Decision> decisions;
  std::size_t samples = 0;   // valid samples
  std::size_t fit_points = 0;  // samples the fits used
  Moments moments;
  Vec3 sigma = Vec3::Zero();        // √eigenvalues
  Vec3 noise_sigma = Vec3::Zero();  // along each principal axis
  int significant_axes = 0;
  // Dimensionality features from σ: linearity (σ1 − σ2)/σ1, planarity (σ2 − σ3)/σ1, scattering σ3/σ1.
  double linearity = 0, planarity = 0, scattering = 0;
  Clipping clipping;
  std::optional<Line> line;            // the principal line (linear clusters)
  std::optional<LineSearch> body_only;  // the robust body line before the two-line model
  double line_tolerance = 0;            // τ: a sample within it of a line lies on the line
  std::optional<TwoLines> two_lines;
  // L, skewed-T and P: the colour the highlight adds, from the samples clearly off the body line
  // (analyzer/highlight_branch.h).
  std::optional<HighlightBranch> highlight_branch;
  std::optional<Plane> plane;          // principal plane through the mean (normal = third axis)
  std::optional<Plane> black_plane;    // best plane through black: the dichromatic plane
  std::optional<PrincipalCurve> curve;
  std::optional<GammaFit> gamma;
  std::vector<ClusterShape> unclipped;  // for clipped clusters: the shape of the samples off the faces
  // For clusters with faces only at black: the shape of the samples clear of black (analyzer/clipping.h), whose
  // plane through black the truncated noise does not tilt, and per face channel the level of the other two
  // channels' sum above which they lie (NaN for a channel without a face).
  std::vector<ClusterShape> clear_of_black;
  std::array<double, 3> clear_levels{std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::quiet_NaN(),
                                     std::numeric_limits<double>::quiet_NaN()};
};

// The shape the light made, as far as it can be read: a clipped cluster's samples off its faces (`unclipped`)
// when there are any; any other cluster itself.
inline const ClusterShape& off_the_faces(const ClusterShape& s) {
  return s.shape == ShapeClass::Clipped && !s.unclipped.empty() && s.unclipped.front().samples > 0 ? s.unclipped.front() : s;
}

inline constexpr double kNoLevel = std::numeric_limits<double>::infinity();

// What the cluster is judged against.
struct ShapeContext {
  // The image's noise (analyzer/noise_level.h); none: only the floor.
  const ImageNoise* noise = nullptr;
  double quantisation_sigma = 0;  // step / √12 for integer images: the floor without an image noise
  std::array<double, 3> high_levels{kNoLevel, kNoLevel, kNoLevel};  // clipping levels (analyzer/clipping.h); none known: +∞
  ClippingRules clipping;               // whether they are known, and the lower limits
  std::uint64_t seed = 1;
  int threads = 0;
  ShapeCriteria criteria;
};

// Measures and classifies samples [i][channel].
ClusterShape analyse_shape(std::span<const float> rgb, const ShapeContext& context);

// The plane through black nearest to the points in the least-squares sense (its normal is the eigenvector
// of Σ x xᵀ with the smallest eigenvalue), oriented with a non-negative component sum.
Plane plane_through_black(const std::vector<Vec3>& points);

}  // namespace ct::analyzer
