// SPDX-License-Identifier: Apache-2.0
// The statistical baselines of colour constancy (analyzer/colour_constancy.h) on images whose answer is known:
// where a method's assumption holds exactly its estimate is the light, and otherwise the closed form it computes.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "analyzer/colour_constancy.h"
#include "core/random.h"

namespace ct::analyzer {
namespace {

constexpr int kW = 48, kH = 32;

// An image of reflectance(x, y) (an RGB triple) lit by `light`, channel by channel.
template <typename Reflectance>
std::vector<float> lit_image(const Vec3& light, Reflectance reflectance) {
  std::vector<float> rgb;
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x) {
      const Vec3 r = reflectance(x, y);
      for (int c = 0; c < 3; ++c) rgb.push_back(static_cast<float>(r[c] * light[c]));
    }
  return rgb;
}

// Double rounding of float pixels and the sums (1e-7 relative), and the normalisation: 1e-6 in each component.
void expect_direction(const Vec3& got, const Vec3& want, const std::string& what) {
  const Vec3 w = want.normalized();
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(got[c], w[c], 1e-6) << what << " channel " << c;
}

// Grey surfaces of random lightness in blocks (edges of every strength) under a coloured light: every method's
// assumption holds, so every estimate is the light.
TEST(ColourConstancy, EveryMethodFindsTheLightWhereTheSurfacesAreGrey) {
  const Vec3 light(0.9, 0.6, 0.3);
  std::vector<double> greys;
  Random random(7, 1);
  for (int i = 0; i < 64; ++i) greys.push_back(0.05 + 0.9 * random.uniform());
  const std::vector<float> image = lit_image(light, [&](int x, int y) {
    const double g = greys[static_cast<std::size_t>((y / 4) * 8 + (x / 6)) % greys.size()];
    return Vec3(g, g, g);
  });
  for (const MinkowskiSettings& method : baseline_methods())
    expect_direction(minkowski_estimate(image, kW, kH, {}, method), light, method.name);
}

// Two coloured halves, a and b, under a white light: grey world is their mean, shades of grey the Minkowski mean
// ((a^6 + b^6) / 2)^(1/6), white patch the per-channel maximum; the grey edges see one step, of height |a − b|
// per channel and one spatial profile for all three, so they point along |a − b| whatever σ.
TEST(ColourConstancy, TwoColoursGiveEachMethodsClosedForm) {
  const Vec3 a(0.8, 0.3, 0.1), b(0.2, 0.4, 0.6);
  const std::vector<float> image = lit_image(Vec3::Ones(), [&](int x, int) { return x < kW / 2 ? a : b; });
  const auto method = [](const std::string& name) {
    for (const MinkowskiSettings& m : baseline_methods())
      if (m.name == name) return m;
    throw std::logic_error(name);
  };
  expect_direction(minkowski_estimate(image, kW, kH, {}, method("grey world")), (a + b) / 2, "grey world");
  Vec3 minkowski;
  for (int c = 0; c < 3; ++c) minkowski[c] = std::pow((std::pow(a[c], 6) + std::pow(b[c], 6)) / 2, 1.0 / 6);
  expect_direction(minkowski_estimate(image, kW, kH, {}, method("shades of grey")), minkowski, "shades of grey");
  expect_direction(minkowski_estimate(image, kW, kH, {}, method("white patch")), a.cwiseMax(b), "white patch");
  for (const std::string edge : {"grey edge 1", "grey edge 2"})
    expect_direction(minkowski_estimate(image, kW, kH, {}, method(edge)), (a - b).cwiseAbs(), edge);
}

// Pixels left out (clipped, say) do not count, nor, for the edges, anything whose derivative reads them: a
// saturated white block in a grey scene under a coloured light, masked, leaves every estimate on the light.
TEST(ColourConstancy, PixelsLeftOutDoNotCount) {
  const Vec3 light(0.5, 0.7, 0.9);
  std::vector<float> image = lit_image(light, [](int x, int y) {
    const double g = ((x / 8 + y / 8) % 2) ? 0.3 : 0.6;
    return Vec3(g, g, g);
  });
  std::vector<std::uint8_t> usable(static_cast<std::size_t>(kW * kH), 1);
  for (int y = 10; y < 20; ++y)
    for (int x = 20; x < 30; ++x) {
      const std::size_t p = static_cast<std::size_t>(y * kW + x);
      usable[p] = 0;
      for (int c = 0; c < 3; ++c) image[3 * p + static_cast<std::size_t>(c)] = 1.0f;  // clipped: the light's colour lost
    }
  for (const MinkowskiSettings& method : baseline_methods())
    expect_direction(minkowski_estimate(image, kW, kH, usable, method), light, method.name);
  // Nothing usable: no estimate.
  std::vector<std::uint8_t> none(usable.size(), 0);
  EXPECT_EQ(minkowski_estimate(image, kW, kH, none, baseline_methods()[0]), Vec3::Zero());
}

// The block bootstrap's spread: nil where every block says the same (grey surfaces under one light), larger the
// more the blocks disagree (coloured blocks whose colours spread more about grey; for the edges, which are the
// colours' differences and scale with the spread, the same), the same numbers for the same seed, and
// another seed within the bootstrap's own sampling error (200 replicates: about 1/√400 = 5 % of σ for a smooth
// statistic; 25 % allowed).
TEST(ColourConstancy, BootstrapUncertaintyFollowsHowMuchTheBlocksDisagree) {
  const Vec3 light(0.9, 0.6, 0.3);
  const std::vector<float> grey = lit_image(light, [](int x, int y) {
    const double g = ((x / 6 + y / 4) % 3 + 1) * 0.25;
    return Vec3(g, g, g);
  });
  for (const MinkowskiSettings& method : baseline_methods()) {
    const BaselineEstimate e = baseline_estimate(grey, kW, kH, {}, method);
    EXPECT_LT(e.uncertainty_deg, 1e-4) << method.name;
    EXPECT_EQ(e.pixels > 0, true) << method.name;
  }
  // Blocks of random colours whose chroma is scaled by `spread` about grey.
  const auto coloured = [&](double spread) {
    Random random(3, 5);
    std::vector<Vec3> colours;
    for (int i = 0; i < 48; ++i) {
      const Vec3 offset(random.uniform() - 0.5, random.uniform() - 0.5, random.uniform() - 0.5);
      colours.push_back(Vec3::Constant(0.5) + spread * offset);
    }
    return lit_image(light, [&](int x, int y) { return colours[static_cast<std::size_t>((y / 4) * 8 + x / 6) % 48]; });
  };
  const std::vector<float> narrow = coloured(0.2), wide = coloured(0.8);
  for (const MinkowskiSettings& method : baseline_methods()) {
    const BaselineEstimate a = baseline_estimate(narrow, kW, kH, {}, method), b = baseline_estimate(wide, kW, kH, {}, method);
    EXPECT_GT(a.uncertainty_deg, 0.01) << method.name;
    if (method.order == 0) {
      EXPECT_GT(b.uncertainty_deg, a.uncertainty_deg) << method.name;
    } else {  // the edges are the colours' differences, which scale with the spread: the same directions, the same σ
      EXPECT_NEAR(b.uncertainty_deg, a.uncertainty_deg, 1e-6 * a.uncertainty_deg) << method.name;
    }
    const BaselineEstimate again = baseline_estimate(wide, kW, kH, {}, method);
    EXPECT_EQ(again.uncertainty_deg, b.uncertainty_deg) << method.name;
    // A maximum's bootstrap is coarse (a resample misses the brightest block or not), so white patch's σ is only
    // held to a factor of two between seeds.
    const BaselineEstimate other = baseline_estimate(wide, kW, kH, {}, method, 200, 2);
    const double tolerance = std::isinf(method.p) ? 1.0 : 0.25;
    EXPECT_NEAR(other.uncertainty_deg, b.uncertainty_deg, tolerance * b.uncertainty_deg) << method.name;
  }
}

}  // namespace
}  // namespace ct::analyzer
