// SPDX-License-Identifier: Apache-2.0
#pragma once
// Lights seen directly — a lamp, the sun, a window's panes — found by their brightness against the image's. A
// surface's radiance is its albedo times the irradiance over π; a light's is the irradiance it gives over the solid
// angle it fills. So a lamp filling 0.01 sr is some 300 times as bright as a white surface it lights, the sun some
// 10⁵ times, and the median surface of a scene (albedo about 0.2, partly shaded) a fifth of a white one or less. On
// the test set of photographs (tests/data/photos) the brightest pixel of a white surface reaches 78 times the
// image's median (a napkin beside an oil lamp), while the lamps, the suns and a window's panes reach 600 to 70 000.
//
// A light is a connected set of pixels at least kLightSeed times the image's median brightness, grown (by hysteresis,
// as Canny grows edges) over its neighbours at least kLightGrow times it — the glow around a sun, a lamp's rim — and
// then by kLightMargin pixels, where the light's edge mixes with what lies behind it. It is no surface: every
// estimate of the light's colour leaves its pixels out; it stands beside them as a reference, its colour the mean of
// its pixels'. A light dimmer than kLightSeed times the median cannot be told from a white surface by its brightness:
// in an 8-bit file, whose range is some 20 to 50 times its median, a lamp is either clipped (and left out as such)
// or not found.

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "analyzer/analysis_image.h"
#include "analyzer/moments.h"

namespace ct::analyzer {

inline constexpr double kLightSeed = 200.0;
inline constexpr double kLightGrow = 50.0;
inline constexpr int kLightMargin = 2;

struct LightInView {
  std::string name;         // "light at (x, y)": its brightest pixel
  int x = 0, y = 0;         // its brightest pixel
  Vec3 rgb = Vec3::Zero();  // its mean colour, unit
  double brightness = 0;    // its brightest pixel's brightness over the image's median (brightness: the mean of R, G, B)
  std::size_t pixels = 0;   // with the margin
};

struct LightsInView {
  std::vector<LightInView> lights;    // brightest first
  std::vector<std::uint8_t> mask;     // per pixel: nonzero on a light (with its margin)
  double median_brightness = 0;       // the image's, over the pixels counted
};

// `rgb`: width × height × 3 linear values; `counted` (empty: every finite pixel) marks the pixels whose brightness
// makes the image's median (not clipped, not black). Lights are sought among every finite pixel.
LightsInView find_lights_in_view(const RgbImage& image, std::span<const std::uint8_t> counted);

}  // namespace ct::analyzer
