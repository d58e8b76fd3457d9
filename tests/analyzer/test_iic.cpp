// SPDX-License-Identifier: Apache-2.0
// The inverse-intensity chromaticity estimator (analyzer/iic.h) on synthetic dichromatic surfaces whose light is
// known: I = m_d·B + m_s·G with m_d constant across each highlight (the method's assumption). Noise-free, the
// estimate is the light to float rounding; with noise, within its own stated uncertainty; surfaces without a
// highlight, or whose body colour is the light's, give no evidence; two lights give one of them, with the others
// counted as disagreeing and an uncertainty of the order of the angle between them.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <numbers>
#include <random>
#include <vector>

#include <Eigen/Geometry>

#include "analyzer/iic.h"

namespace ct::test {
namespace {

using analyzer::estimate_iic;
using analyzer::IicResult;
using analyzer::IicSurface;
using analyzer::Vec3;

const Vec3 kTungsten(1.0, 0.8, 0.55);   // a tungsten-like light
const Vec3 kBluish(0.6, 0.8, 1.0);  // a skylight-like light
const std::vector<Vec3> kBodies = {{0.70, 0.20, 0.10}, {0.10, 0.50, 0.20}, {0.20, 0.30, 0.80},
                                   {0.60, 0.55, 0.10}, {0.50, 0.10, 0.45}};

double angle_deg(const Vec3& a, const Vec3& b) {
  return std::atan2(a.cross(b).norm(), a.dot(b)) * 180.0 / std::numbers::pi;
}

// One surface of body colour `body` under `light`: `diffuse` pixels of random shading m_d in [0.2, 1] and no
// highlight, then `highlight` pixels of one shading m_d (drawn in [0.5, 0.9]: the highlight's part of the
// surface) and a random highlight m_s in [0, 0.6]; Gaussian noise of standard deviation `noise` in each channel.
// `shading_change` > 0 breaks the method's assumption: m_d varies across the highlight by up to that fraction.
std::vector<float> dichromatic_surface(const Vec3& body, const Vec3& light, std::mt19937& generator, double noise,
                                       int diffuse = 240, int highlight = 160, double shading_change = 0) {
  std::uniform_real_distribution<double> shading(0.2, 1.0), highlight_shading(0.5, 0.9), specular(0.0, 0.6),
      change(-shading_change, shading_change);
  std::normal_distribution<double> gaussian(0.0, 1.0);
  std::vector<float> rgb;
  const auto add = [&](double m_d, double m_s) {
    const Vec3 c = m_d * body + m_s * light;
    for (int k = 0; k < 3; ++k) rgb.push_back(static_cast<float>(c[k] + (noise > 0 ? noise * gaussian(generator) : 0.0)));
  };
  for (int i = 0; i < diffuse; ++i) add(shading(generator), 0.0);
  const double m_d = highlight_shading(generator);
  for (int i = 0; i < highlight; ++i) add(m_d * (1 + change(generator)), specular(generator));
  return rgb;
}

// Surfaces hold spans: the pixel storage lives beside them.
struct Scene {
  std::vector<std::vector<float>> pixels;
  std::vector<IicSurface> surfaces() const {
    std::vector<IicSurface> out;
    for (const std::vector<float>& p : pixels) out.push_back({p});
    return out;
  }
};

Scene scene(const Vec3& light, std::uint32_t seed, double noise) {
  std::mt19937 generator(seed);
  Scene s;
  for (const Vec3& body : kBodies) s.pixels.push_back(dichromatic_surface(body, light, generator, noise));
  return s;
}

// Noise-free, the pixels are exact but for float rounding (2⁻²⁴ ≈ 6·10⁻⁸ relative): the line's direction is
// off by that over the highlight's relative extent (m_s·|G| over |I|, at least a fifth here), ~3·10⁻⁷ rad, or
// 2·10⁻⁵°. 10⁻³° leaves a factor of 50 for the principal axis's own rounding.
constexpr double kExactDeg = 1e-3;

TEST(Iic, NoiseFreeSurfacesGiveTheLight) {
  for (const Vec3& light : {kTungsten, kBluish})
    for (std::uint32_t seed = 1; seed <= 5; ++seed) {
      const Scene s = scene(light, seed, 0.0);
      const IicResult r = estimate_iic(s.surfaces());
      ASSERT_TRUE(r.estimate) << r.reason;
      EXPECT_LT(angle_deg(r.estimate->rgb, light), kExactDeg) << "seed " << seed;
      EXPECT_NEAR(r.estimate->rgb.norm(), 1.0, 1e-12);
      EXPECT_GT(r.estimate->rgb.sum(), 0.0);
      EXPECT_EQ(r.estimate->surfaces, kBodies.size());
      EXPECT_EQ(r.estimate->disagreeing, 0u);
      // Every highlight pixel but the few whose m_s is too small to move the chromaticity by min_highlight_shift.
      EXPECT_LE(r.estimate->pixels, 160u * kBodies.size());
      EXPECT_GE(r.estimate->pixels, 150u * kBodies.size());
      EXPECT_LT(r.estimate->uncertainty_deg, kExactDeg);
    }
}

// With noise (0.005 per channel, about 1 % of a mid-grey pixel), over 20 scenes: the angle to the light is a
// two-dimensional error whose root-mean-square the stated uncertainty estimates. For a two-dimensional normal
// error of that RMS, P(angle > k·RMS) = exp(−k²): 2 % beyond 2σ, 10⁻⁴ beyond 3σ. So every scene within 3σ, at
// least 17 of 20 within 2σ (0.4 expected beyond), and the mean of (angle / σ)², 1 when the uncertainty is right
// (an exponential's mean: ±0.22 over 20), between 0.35 and 2: neither understated nor grossly overstated.
TEST(Iic, WithNoiseTheErrorIsWithinTheStatedUncertainty) {
  constexpr double kNoise = 0.005;
  for (const Vec3& light : {kTungsten, kBluish}) {
    int within_two = 0;
    double mean_square_ratio = 0;
    for (std::uint32_t seed = 1; seed <= 20; ++seed) {
      const Scene s = scene(light, 100 + seed, kNoise);
      const IicResult r = estimate_iic(s.surfaces());
      ASSERT_TRUE(r.estimate) << r.reason;
      const double error = angle_deg(r.estimate->rgb, light), sigma = r.estimate->uncertainty_deg;
      EXPECT_GT(sigma, 0.0);
      EXPECT_LT(sigma, 2.0) << "a highlight of 160 pixels at 1 % noise measures the light to well within 2°";
      EXPECT_LE(error, 3 * sigma) << "seed " << seed;
      EXPECT_EQ(r.estimate->surfaces, kBodies.size()) << "seed " << seed;
      within_two += error <= 2 * sigma;
      mean_square_ratio += (error / sigma) * (error / sigma) / 20;
    }
    EXPECT_GE(within_two, 17);
    EXPECT_GT(mean_square_ratio, 0.35);
    EXPECT_LT(mean_square_ratio, 2.0);
  }
}

// Diffuse surfaces (m_s = 0) lie on horizontal lines in IIC space whose intercepts are their body colours: no
// evidence of the light, with or without noise.
TEST(Iic, SurfacesWithoutHighlightsGiveNoEstimate) {
  for (const double noise : {0.0, 0.005}) {
    std::mt19937 generator(7);
    Scene s;
    for (const Vec3& body : kBodies) s.pixels.push_back(dichromatic_surface(body, kTungsten, generator, noise, 400, 0));
    const IicResult r = estimate_iic(s.surfaces());
    EXPECT_FALSE(r.estimate) << "noise " << noise;
    EXPECT_NE(r.reason.find("no surface gave a highlight line"), std::string::npos) << r.reason;
  }
  EXPECT_FALSE(estimate_iic({}).estimate);
  EXPECT_EQ(estimate_iic({}).reason, "no surfaces");
}

// A surface whose body colour is the light's has every pixel at the light's chromaticity, highlight or not: its
// line is horizontal, and it is no evidence (its intercept would equal the light's here, but in general it is only
// the body colour). Alone it gives no estimate; beside other surfaces it is not counted.
TEST(Iic, ABodyColourAtTheLightsGivesNoEvidence) {
  for (const double noise : {0.0, 0.005}) {
    std::mt19937 generator(11);
    Scene alone;
    alone.pixels.push_back(dichromatic_surface(0.5 * kTungsten, kTungsten, generator, noise));
    const IicResult r = estimate_iic(alone.surfaces());
    EXPECT_FALSE(r.estimate) << "noise " << noise;
    EXPECT_FALSE(r.reason.empty());

    Scene with_others = scene(kTungsten, 12, noise);
    with_others.pixels.push_back(alone.pixels.front());
    const IicResult both = estimate_iic(with_others.surfaces());
    ASSERT_TRUE(both.estimate) << both.reason;
    EXPECT_EQ(both.estimate->surfaces, kBodies.size());
    EXPECT_EQ(both.estimate->disagreeing, 0u);
  }
}

// A body colour near the light's (chromaticity 0.007 away) has highlight pixels, but they change the chromaticity
// by less than settings.min_chromaticity_change: an intercept extrapolated from so small a change is no evidence.
TEST(Iic, AHighlightThatBarelyChangesTheChromaticityIsNoEvidence) {
  const Vec3 near_light = kTungsten / kTungsten.sum() + Vec3(0.005, -0.005, 0.0);
  std::mt19937 generator(13);
  Scene s;
  s.pixels.push_back(dichromatic_surface(near_light, kTungsten, generator, 0.0));
  const IicResult r = estimate_iic(s.surfaces());
  EXPECT_FALSE(r.estimate);
  EXPECT_NE(r.reason.find("1 whose highlight changes the chromaticity by less than 0.01"), std::string::npos) << r.reason;
}

// Highlights of two lights (a surface under each): the estimate is one light, not a mixture: the intercept with
// most support, ties going to the one with more highlight pixels (here the first surface, 200 against 160). The
// other surface is counted as disagreeing, and the bootstrap over surfaces draws the other light's surface alone
// in a quarter of its replicates, so the uncertainty is about half the angle between the lights: well above the
// noise-free scatter, stating that the scene's highlights disagree.
TEST(Iic, TwoLightsGiveOneOfThemWithALargeUncertainty) {
  std::mt19937 generator(21);
  Scene s;
  s.pixels.push_back(dichromatic_surface(kBodies[0], kTungsten, generator, 0.0, 240, 200));
  s.pixels.push_back(dichromatic_surface(kBodies[2], kBluish, generator, 0.0, 240, 160));
  const IicResult r = estimate_iic(s.surfaces());
  ASSERT_TRUE(r.estimate) << r.reason;
  const double between = angle_deg(kTungsten, kBluish);
  EXPECT_LT(angle_deg(r.estimate->rgb, kTungsten), kExactDeg);
  EXPECT_EQ(r.estimate->surfaces, 1u);
  EXPECT_EQ(r.estimate->disagreeing, 1u);
  EXPECT_GT(r.estimate->uncertainty_deg, 0.3 * between);
  EXPECT_LT(r.estimate->uncertainty_deg, 0.7 * between);

  // Three surfaces under the warm light and one under the bluish: the majority's light; the bootstrap rarely
  // draws more bluish than warm surfaces, so the uncertainty is smaller, but still above the noise-free scatter.
  Scene majority = scene(kTungsten, 22, 0.0);
  majority.pixels.resize(3);
  majority.pixels.push_back(s.pixels[1]);
  const IicResult m = estimate_iic(majority.surfaces());
  ASSERT_TRUE(m.estimate) << m.reason;
  EXPECT_LT(angle_deg(m.estimate->rgb, kTungsten), kExactDeg);
  EXPECT_EQ(m.estimate->surfaces, 3u);
  EXPECT_EQ(m.estimate->disagreeing, 1u);
  EXPECT_GT(m.estimate->uncertainty_deg, 0.05 * between);
}

// Shading that changes across each highlight (m_d within ±5 %, noise-free) breaks the method's assumption: each
// surface's line tilts towards its body colour. The bodies differ, so the tilts differ, and the bootstrap over
// surfaces sees them: the error is no longer float rounding, but within the stated uncertainty. (A tilt that
// every surface shared, bodies all of one hue, would not be seen: see analyzer/iic.h.)
TEST(Iic, ShadingAcrossTheHighlightsShowsInTheUncertainty) {
  for (std::uint32_t seed = 1; seed <= 10; ++seed) {
    std::mt19937 generator(200 + seed);
    Scene s;
    for (const Vec3& body : kBodies) s.pixels.push_back(dichromatic_surface(body, kTungsten, generator, 0.0, 240, 160, 0.05));
    const IicResult r = estimate_iic(s.surfaces());
    ASSERT_TRUE(r.estimate) << r.reason;
    const double error = angle_deg(r.estimate->rgb, kTungsten);
    EXPECT_GT(error, kExactDeg) << "seed " << seed;
    EXPECT_LE(error, 3 * r.estimate->uncertainty_deg) << "seed " << seed;
  }
}

// The same inputs give the same bytes: the bootstrap's generator is seeded and counter-based.
TEST(Iic, Deterministic) {
  const Scene s = scene(kBluish, 31, 0.005);
  const IicResult a = estimate_iic(s.surfaces()), b = estimate_iic(s.surfaces());
  ASSERT_TRUE(a.estimate && b.estimate);
  EXPECT_EQ(std::memcmp(a.estimate->rgb.data(), b.estimate->rgb.data(), 3 * sizeof(double)), 0);
  EXPECT_EQ(std::memcmp(&a.estimate->uncertainty_deg, &b.estimate->uncertainty_deg, sizeof(double)), 0);
  EXPECT_EQ(a.estimate->pixels, b.estimate->pixels);
  EXPECT_EQ(a.estimate->surfaces, b.estimate->surfaces);
  EXPECT_EQ(a.reason, b.reason);
}

TEST(Iic, RejectsValuesThatAreNotTriplets) {
  const std::vector<float> four(4, 0.5f);
  EXPECT_THROW(estimate_iic({IicSurface{four}}), std::invalid_argument);
}

}  // namespace
}  // namespace ct::test
