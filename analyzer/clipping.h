// SPDX-License-Identifier: Apache-2.0
#pragma once
// Clipping: samples pressed onto a face of the RGB cube, where one channel stopped at the sensor's or
// the encoding's limit while the others went on changing (the paper's over-exposure artefact), or at
// black.

#include <array>
#include <cstdint>
#include <limits>
#include <span>
#include <vector>

namespace ct::analyzer {

struct ClippedFace {
  int channel = 0;     // 0 R, 1 G, 2 B
  bool high = true;    // the channel's upper limit (else the lower)
  double level = 0;    // the limit's value
  std::size_t count = 0;
  double fraction = 0;  // of the samples
};

struct Clipping {
  std::vector<ClippedFace> faces;  // faces holding at least kFaceFraction of the samples (and 3 samples)
  std::size_t clipped = 0;         // samples on any of those faces
  double fraction = 0;
  std::vector<std::uint8_t> on_face;  // per sample: 1 if on one of the faces
  // Every sample at a channel's limit, whether or not enough of them make a face: a sheen's few pixels at the top
  // are clipped too (a highlight cut off), though too few to flatten the cluster.
  std::array<std::size_t, 3> at_top{};    // samples at or above the channel's upper limit
  std::array<std::size_t, 3> at_black{};  // at or below its lower limit, with another channel above its own
  // Of the samples at black in channel c: the median of their brightest channel, as stored. Dim pixels under the
  // file's black, or a bright colour outside its gamut, have the same face; this tells them apart.
  std::array<double, 3> black_brightest_median{};
  // What "dim" is measured against: the top of the file's range — the largest finite upper limit, else (no limit
  // known) the brightest channel of the brightest sample. Dim: under kDimShare of it.
  double top = 0;
  // Whether the upper limits are ones the camera or the file clipped at (ClippingRules::known_high); otherwise they
  // are each channel's largest value, and a few samples there are no clipping unless they make a face.
  bool known_high = false;
};
inline constexpr double kDimShare = 0.25;

// A face counts when at least this share of the samples lies on it: a few pixels exactly at a channel's
// maximum happen without clipping.
constexpr double kFaceFraction = 0.005;
// … and, when the upper levels are only estimated (each channel's largest value in a float image), and on every
// lower face, only when the other channels keep changing on it (their range above this share of the level; on a
// lower face, of the other channels' largest value on it): a flat patch that happens to hold a channel's largest or
// smallest value is not clipped.
constexpr double kFaceSpread = 0.01;

// Where the faces are. `known_high`: the upper levels are limits the camera or the file format clipped at
// (the metadata's white level, an integer format's full scale), so every sample at one is clipped, whatever
// the other channels do — a region clipped in all three channels is wholly clipped. Otherwise they are each
// channel's largest value, and the spread rule above applies. `low`: the lower limits (0, or −black level
// once a camera's black level has been subtracted).
struct ClippingRules {
  bool known_high = false;
  std::array<double, 3> low{0, 0, 0};
};

// Samples [i][channel] at or above high_levels[c] lie on the high face of c; at or below rules.low[c], with
// another channel above its low limit, on its low face (a pixel black in all three channels is dark, not
// clipped).
Clipping find_clipping(std::span<const float> rgb, const std::array<double, 3>& high_levels, const ClippingRules& rules);

// A face at a channel's upper limit: a highlight or a bright colour cut off, where what lay beyond is lost.
bool reaches_the_top(const Clipping& c);
// Faces, all at the lower limits: channels at the file's black (a colour outside its gamut, dim pixels under its
// black); the brightest samples, a highlight among them, are whole.
bool only_at_black(const Clipping& c);


// The samples clear of black. A channel held at its lower limit lost the noise below it, so the samples just above
// the limit are those whose noise happened to be positive: biased off the face, they tilt the cluster's plane, and
// cutting at any level of that channel only moves the bias to the cut. The other two channels carry noise of their
// own, so for each channel with a face at black the samples are ordered by the sum of the other two instead: going
// down from the brightest (in log-spaced buckets of the sum, linear in time), that channel starts to reach black at
// some level of the sum. Above every face channel's
// level (where fewer than kClearShare of the samples reach black) the samples kept their whole noise; those, less the
// few still at black, are clear. Empty when even the brightest samples reach black.
inline constexpr double kClearShare = 0.01;
struct ClearOfBlack {
  std::vector<float> rgb;  // the samples clear of black, [i][channel]
  // Per channel with a face at black: the level of the other two channels' sum above which it no longer reaches
  // black; NaN for the other channels.
  std::array<double, 3> level{std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::quiet_NaN(),
                              std::numeric_limits<double>::quiet_NaN()};
};
ClearOfBlack clear_of_black(std::span<const float> rgb, const Clipping& clipping, const std::array<double, 3>& low);
}  // namespace ct::analyzer
