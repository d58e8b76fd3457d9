// SPDX-License-Identifier: Apache-2.0
#pragma once
// Lights seen directly — a lamp, the sun, a window's panes — found by their brightness against the image's. A
// surface's radiance is its albedo times the irradiance over π; a light's is the irradiance it gives over the solid
// angle it fills. So a lamp filling 0.01 sr is some 300 times as bright as a white surface it lights, the sun some
// 10⁵ times. The surfaces' level is read two ways, and a light must pass both: the image's median brightness (the
// median surface of a scene, albedo about 0.2 and partly shaded, is a fifth of a white one or less), and its 95th
// percentile (a twentieth of the frame is lit surfaces, not lights), which holds where a dark background above the
// file's black holds the median down: were the night background of the oil-lamp still life counted, its white napkin
// would stand at 283 times the median, but at 2 times the 95th percentile. On the test set of photographs
// (tests/data/photos) a white surface's brightest pixel reaches at most 78 times the median and 3.6 times the 95th
// percentile, while the lamps, the suns and a window's panes reach 600 to 100 000 times the median and 11 to 28 000
// times the 95th percentile.
//
// A light is a connected set of pixels at least kLightSeed times the median and kLightOverLit times the 95th
// percentile, grown (by hysteresis, as Canny grows edges) over its neighbours at least kLightGrow times the median and
// above the 95th percentile — the glow around a sun, a lamp's rim — and then by kLightMargin pixels, where the
// light's edge mixes with what lies behind it. A glossy surface mirrors a light at a few per cent of its radiance
// (a dielectric's Fresnel reflectance), so the mirror image of a small bright light can pass too: the core of a glazed
// bagel's highlight under an oil lamp is 28 times the 95th percentile. Either way it shows the light's colour whole,
// with no body colour: every estimate of the light's colour leaves its pixels out, and it stands beside them as a
// reference, its colour the mean of its pixels'. A region keeps them in its cluster unless they make most of it. A
// light dimmer than that cannot be told from a white surface by its brightness: in an 8-bit file, whose range is
// some 20 to 50 times its median, a lamp is either clipped (and left out as such) or not found.

#include <array>
#include <cstdint>
#include <limits>
#include <span>
#include <string>
#include <vector>

#include "analyzer/analysis_image.h"
#include "analyzer/moments.h"

namespace ct::analyzer {

inline constexpr double kLightSeed = 200.0;
inline constexpr double kLightOverLit = 10.0;
inline constexpr double kLightGrow = 50.0;
inline constexpr int kLightMargin = 2;
// The report names the brightest kLightsNamed (analysis.json lists every one): a still life by oil lamps mirrors its
// two flames in some fifty glints on glass, glaze and cutlery.
inline constexpr std::size_t kLightsNamed = 8;

struct LightInView {
  std::string name;         // "light at (x, y)": its brightest pixel
  int x = 0, y = 0;         // its brightest pixel
  Vec3 rgb = Vec3::Zero();  // its mean colour, unit
  double brightness = 0;    // its brightest pixel's brightness over the image's median (brightness: the mean of R, G, B)
  std::size_t pixels = 0;   // with the margin
  std::size_t clipped = 0;  // of those, at or above a channel's known clipping level: its colour is then cut, no reference
};

struct LightsInView {
  std::vector<LightInView> lights;    // brightest first
  std::vector<std::uint8_t> mask;     // per pixel: nonzero on a light (with its margin)
  double median_brightness = 0;       // the image's, over the pixels counted
  double lit_brightness = 0;          // its 95th percentile
  double seed_level = 0;              // a light's brightest pixel reaches at least this brightness
};

// `rgb`: width × height × 3 linear values; `counted` (empty: every finite pixel) marks the pixels whose brightness
// makes the image's median (not clipped, not black). Lights are sought among every finite pixel; `high_levels` are
// the channels' known clipping levels (a camera's white level, an integer file's full scale; +∞ where none is
// known), at which a light's pixels count as clipped.
LightsInView find_lights_in_view(const RgbImage& image, std::span<const std::uint8_t> counted,
                                 const std::array<double, 3>& high_levels = {std::numeric_limits<double>::infinity(),
                                                                             std::numeric_limits<double>::infinity(),
                                                                             std::numeric_limits<double>::infinity()});

}  // namespace ct::analyzer
