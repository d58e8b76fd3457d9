// SPDX-License-Identifier: Apache-2.0
#pragma once
// Automatic segmentation by physics (docs/analyze.md, "Automatic segmentation").
//
// The anchor is Klinker, Shafer & Kanade (IJCV 1990): in linear light, a matte surface's colours lie on a
// line through black (its body colour, scaled by shading), and its highlight adds the illuminant's colour,
// so object and highlight together fill a dichromatic plane; the highlight's line leaves the body line at a
// point of its upper range, not at black. Regions are grown from linear colour clusters and then extended
// over such planes, so that a highlight stays with its object:
//
//  1. The image is read in linear light and area-averaged to a working size of about
//     `working_megapixels` (never enlarged), so that the same objects give the same segments at any size.
//  2. The noise of the working image is estimated once for the whole image (Immerkær 1996, "Fast noise
//     variance estimation", with a low quantile of |3×3 Laplacian difference| per brightness band so that
//     flat areas decide it, and values clipped at black or at the top left out), as σ² = a + b·v + c·v² per
//     channel in the values as the file stores them (read, shot and signal-proportional noise for a linear
//     file, fitted in relative terms so that the dark bands count as much as the bright; what the encoding's
//     steps and compression did, for an sRGB or gamma file), carried into linear light by the curve's
//     slope, plus the quantisation noise of integer files (step/√12 of the stored code, in linear light).
//  3. Pixels darker than `dark` noise σ have no reliable colour direction and are left unassigned ("dark").
//  4. Linear colour clusters grow over the pixel graph (8-neighbours, the edges taken in increasing order of
//     the angle between the two colours in units of its noise σ, as in Felzenszwalb & Huttenlocher's graph
//     merging): shading does not turn a colour, an edge between objects does. No step above `tolerance` σ is
//     taken, and two parts join only while their mean colour directions differ by less than `tolerance`
//     times the noise of those means plus `angle_deg`, so that a gradual drift cannot chain objects together.
//     Parts that a slow drift of one surface's colour split meet along a boundary with no edge (a median step
//     across it of at most 1.5 σ, or of at most 2.5 times the median step within the smoother part: no sharper
//     than the surface's own texture) and join if their mean directions differ by less than 3 · angle_deg beyond
//     their noise, and if every part that was well measured before these joins stays within that of every other
//     one in the joined part, so that a run of small joins cannot carry one surface's colour into another's.
//  5. Dichromatic extension: a brighter neighbour B of a region A, at most a quarter of A's size and bordered
//     by A on at least 30 % of its boundary, joins A when B's colours are A's body colour plus one other
//     colour (the mean colours of B's rings, pixels at the same distance from B's edge, lie in a plane with
//     A's body line), their turn away from A's body colour grows from B's edge inwards, and their line meets
//     A's body line at a point of A's upper range (30 % to 150 % of its 90th percentile: a highlight), not at
//     black (another matte surface). A mostly clipped neighbour that A surrounds (half its boundary) joins as
//     a clipped highlight.
//  6. Parts smaller than `min_area` of the valid image join a neighbour whose colour they share; those that
//     one segment encloses (nine tenths of their boundary with segments, at least half their boundary with
//     segments) join it as details finer than the smallest segment (speckle, embroidery, a badge); the rest
//     stay unassigned ("small": mixed edge pixels between segments, texture finer than the working size).
//  7. Labels are carried back to full size; pixels on a boundary between segments take the segment whose
//     colour direction is nearest theirs (unassigned working pixels stay unassigned).
// Steps 1 and 7 run on every core, in bands of rows whose sums and counts add in a fixed order: the labels do
// not depend on the thread count.
// Steps 5 and 6 keep each part's neighbours, with the boundary shared with each, and update them as parts join
// (only the joined parts' neighbours): the cost is near-linear in the working pixels and the parts.

#include <cstdint>
#include <string>
#include <vector>

#include "analyzer/image_input.h"
#include "analyzer/moments.h"
#include "analyzer/regions.h"

namespace ct::analyzer {

struct SegmentationOptions {
  double working_megapixels = 0.25;  // the working size (area-averaged); sizes are measured in it
  double min_area = 0.002;           // the smallest segment, as a fraction of the valid pixels
  double tolerance = 6;              // the largest colour-angle step between neighbours in a segment, in noise σ
  double angle_deg = 3;              // how far two parts' mean colour directions may differ beyond their noise
  double dark = 3;                   // pixels with brightness below dark · σ are left unassigned
};

// The noise of the working image: σ_c² = a_c + b_c · v + c_c · v² for channel c at stored value v — in linear light
// for a linear file; for an encoded one (sRGB, gamma) in the values as stored, carried into linear light by
// the curve's slope (`curve`) — never below `floor`.
struct NoiseModel {
  Vec3 a = Vec3::Zero();  // read (dark) noise
  Vec3 b = Vec3::Zero();  // shot noise
  Vec3 c = Vec3::Zero();  // the part proportional to the signal (gain differences, film grain, an HDR merge)
  double floor = 0;
  std::size_t samples = 0;  // pixels the estimate used
  // Integer files: the linear value of each stored code (empty for float files, and for linear integer files
  // whose step is 1), and the pixels averaged into one working pixel; the quantisation noise, step/√12 per
  // stored code, averaged down, is added.
  std::vector<float> codes;
  bool integer = false;
  double averaged = 1;
  // The encoding's curve: the linear value of stored value k·curve_step (empty: linear, a and b in linear light).
  std::vector<float> curve;
  double curve_step = 1;
  double encode(double value) const;  // the stored value of a linear value
  double slope(double value) const;   // d(linear) / d(stored) there
  double sigma(int channel, double value) const;  // in linear light, at linear value `value`
  double quantisation(double value) const;
};

struct Segmentation {
  int width = 0, height = 0;                  // the image
  int working_width = 0, working_height = 0;  // the working size
  std::vector<std::uint16_t> labels;          // per pixel: k for segment k (1 = the largest), 0 for none
                                              // (min_area >= 2e-5 keeps k under 50,000: labels.png is 16-bit)
  std::vector<Region> regions;                // segments by decreasing size, then "unassigned" when any
  std::size_t valid_pixels = 0;               // finite, not transparent, not negative
  std::size_t unassigned_pixels = 0;          // valid pixels in no segment
  std::size_t dark_pixels = 0, small_pixels = 0;  // … of which too dark, or in parts under min_area
  std::size_t highlight_merges = 0, clipped_merges = 0;  // dichromatic extensions made
  std::size_t parts = 0;                      // linear colour clusters after step 4 (what steps 5 and 6 work on)
  NoiseModel noise;
  SegmentationOptions options;
  double seconds = 0;  // wall time of the segmentation

  double unassigned_fraction() const { return valid_pixels ? double(unassigned_pixels) / double(valid_pixels) : 0.0; }
};

// `image`: the analysed layer as stored; `curve` (if not linear) is undone first, with `full_scale` the
// value of a full-scale code (1 for float files). `clip_level`: stored values at or above it are clipped
// (none if <= 0). NaN pixels (unreadable, transparent, negative) are in no segment and not counted as valid.
// Deterministic: the same image and options give the same labels whatever the thread count. With `progress`, a
// progress bar ("segment", core/progress.h) on stderr runs through the steps.
Segmentation segment_image(const RgbImage& image, const std::optional<ToneCurve>& curve, double full_scale,
                           double clip_level, const SegmentationOptions& options, bool progress = false);

// InputError naming the option when a parameter is out of range.
void check_segmentation_options(const SegmentationOptions& options);

}  // namespace ct::analyzer
