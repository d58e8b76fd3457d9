// SPDX-License-Identifier: Apache-2.0
// The principled material (Cycles' Principled BSDF, opaque dielectric): its Fresnel, Cycles' GGX tables as this
// tracer recomputes them, and the lobe's sampling. Agreement with Cycles itself is
// blender.cross_validate.principled (tests/blender/cross_validate.py).
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>

#include "reference_tracer/principled.h"
#include "tests/reference_tracer/lobe_albedo.h"

namespace ct::rt {
namespace {

Vec3 at_cos(double cos_theta, double phi = 0.3) {
  const double s = std::sqrt(1.0 - cos_theta * cos_theta);
  return {s * std::cos(phi), s * std::sin(phi), cos_theta};
}

TEST(Principled, FresnelIsTheDielectricsAtNormalAndGrazingIncidenceAndUnderTotalReflection) {
  for (const double eta : {1.33, 1.5, 2.4}) {
    EXPECT_NEAR(fresnel_dielectric(1.0, eta), std::pow((eta - 1) / (eta + 1), 2), 1e-12) << eta;
    EXPECT_NEAR(fresnel_dielectric(1e-9, eta), 1.0, 1e-6) << eta;
  }
  // Inside glass (η = 1/1.5) beyond the critical angle, asin(1/1.5) = 41.8°: all is reflected.
  EXPECT_EQ(fresnel_dielectric(std::cos(50.0 * std::numbers::pi / 180), 1 / 1.5), 1.0);
  // Brewster's angle, tan θ = η: the p-polarised half vanishes, so F = R_s / 2 = ½ ((η² − 1)/(η² + 1))².
  const double eta = 1.5, brewster = std::atan(eta);
  EXPECT_NEAR(fresnel_dielectric(std::cos(brewster), eta), 0.5 * std::pow((eta * eta - 1) / (eta * eta + 1), 2), 1e-12);
  // The hemispherical average 2∫F(μ)μ dμ, by quadrature, against Kulla and Conty's fit, which Cycles takes for it:
  // 2.5 % low at η = 1.5 (it enters only Multiscatter GGX's compensation, a few per cent of the interface's light).
  double sum = 0;
  const int n = 20000;
  for (int i = 0; i < n; ++i) {
    const double mu = (i + 0.5) / n;
    sum += 2 * mu * fresnel_dielectric(mu, eta) / n;
  }
  EXPECT_NEAR(average_fresnel_dielectric(eta), sum, 0.03 * sum);
}

TEST(Principled, GgxAlbedoTableHasTheKnownAnswers) {
  // At roughness 1 (α = 1) and normal incidence the GGX albedo is 1 − ln 2 (the distribution is uniform over
  // the visible hemisphere of normals); as roughness → 0 every reflection stays above the horizon: 1.
  EXPECT_NEAR(GgxTables::albedo(1.0, 1.0, 256), 1.0 - std::log(2.0), 1e-3);
  const GgxTables& t = GgxTables::get();
  EXPECT_NEAR(t.E(1.0, 1.0), 1.0 - std::log(2.0), 2e-3);
  for (const double mu : {0.05, 0.5, 1.0}) EXPECT_NEAR(t.E(0.0, mu), 1.0, 1e-6) << mu;
  // E_avg = ∫ 2μ E dμ: 1 at roughness 0, and in (0, 1) otherwise.
  EXPECT_NEAR(t.E_avg(0.0), 1.0, 1e-6);
  EXPECT_GT(t.E_avg(1.0), 0.3);
  EXPECT_LT(t.E_avg(1.0), 0.6);
  // As roughness → 0 the microfacet normal is the normal, so S is the Fresnel's rise at μ itself.
  for (const double mu : {0.2, 0.5, 0.9}) {
    const double z = 0.5, f0 = z * z * z * z, eta = (1 + z * z) / (1 - z * z);
    EXPECT_NEAR(GgxTables::fresnel_rise(1e-4, mu, z, 16), (fresnel_dielectric(mu, eta) - f0) / (1 - f0), 1e-6) << mu;
  }
}

// The tables' quadrature is fine enough: doubling its points moves an entry by less than 10⁻³ (principled.cpp).
TEST(Principled, TableQuadratureHasConverged) {
  for (const double r : {0.1, 0.5, 1.0})
    for (const double mu : {1e-4, 0.1, 0.5, 1.0}) {
      EXPECT_NEAR(GgxTables::albedo(r, mu, 64), GgxTables::albedo(r, mu, 128), 1e-3) << r << " " << mu;
      EXPECT_NEAR(GgxTables::fresnel_rise(r, mu, 0.45, 96), GgxTables::fresnel_rise(r, mu, 0.45, 192), 1e-3)
          << r << " " << mu;
    }
}

TEST(Principled, SampleWeightsAreEvalOverPdf) {
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> uni(0.0, 1.0);
  for (const PrincipledLobe& lobe : {PrincipledLobe(2, 0.3, 1.5, true), PrincipledLobe(2, 0.8, 1.6, false),
                                    PrincipledLobe(1, 0.4, 1.5, false)})
    for (double c : {0.1, 0.5, 0.9}) {
      const Vec3 wo = at_cos(c, 1.1);
      for (int i = 0; i < 2000; ++i) {
        const auto s = lobe.sample(wo, Vec2(uni(rng), uni(rng)));
        if (!s) continue;
        ASSERT_NEAR(s->pdf, lobe.pdf(wo, s->wi), 1e-9 * s->pdf);
        ASSERT_NEAR(s->weight, lobe.eval(wo, s->wi) / s->pdf, 1e-9 * s->weight);
      }
    }
}

// What the layering keeps: the base's weight W plus the interface's albedo (Fresnel-weighted, with Multiscatter
// GGX's compensation) is about 1 at every view angle for a white base, as Cycles' layering intends; without the
// compensation the interface loses what single scattering misses, so the sum is lower at high roughness.
TEST(Principled, LayeringKeepsAboutAllTheLightOfAWhiteBase) {
  for (const double r : {0.2, 0.5, 1.0})
    for (const double c : {0.2, 0.5, 1.0}) {
      const PrincipledLobe ms(2, r, 1.5, true), single(2, r, 1.5, false);
      const Vec3 wo = at_cos(c);
      const auto a = test::directional_albedo(ms, wo, 200000, 7), b = test::directional_albedo(single, wo, 200000, 7);
      EXPECT_NEAR(a.mean + ms.diffuse_weight(c), 1.0, 0.02 + 4 * a.se) << r << " " << c;
      EXPECT_GE(a.mean, b.mean - 4 * (a.se + b.se));
      EXPECT_LE(b.mean + single.diffuse_weight(c), 1.0 + 4 * b.se);
    }
  // No interface (η = 1): the base alone, Lambertian.
  const PrincipledLobe none(2, 0.5, 1.0, true);
  EXPECT_EQ(none.eval(at_cos(0.5), at_cos(0.7)), 0.0);
  EXPECT_NEAR(none.diffuse(at_cos(0.5), at_cos(0.7)), 0.7 / std::numbers::pi, 1e-12);
}

// Version 1's base is Burley's diffuse: at normal view and light the Schlick weights (1 − μ)⁵ vanish, leaving
// 1/π whatever the roughness; towards grazing it darkens a smooth surface and brightens a rough one seen back along
// the light (retro-reflection).
TEST(Principled, VersionOneBaseIsBurleysDiffuse) {
  const Vec3 n(0, 0, 1);
  for (const double r : {0.0, 0.5, 1.0})
    EXPECT_NEAR(PrincipledLobe(1, std::max(r, 0.02), 1.5, false).diffuse(n, n) * std::numbers::pi, 1.0, 1e-12) << r;
  const Vec3 grazing = at_cos(0.05, 0.0), view = at_cos(0.05, std::numbers::pi);
  const double smooth = PrincipledLobe(1, 0.02, 1.5, false).diffuse(view, grazing) / grazing.z();
  const double rough = PrincipledLobe(1, 1.0, 1.5, false).diffuse(grazing, grazing) / grazing.z();
  EXPECT_LT(smooth * std::numbers::pi, 0.5);
  EXPECT_GT(rough * std::numbers::pi, 1.0);
}

}  // namespace
}  // namespace ct::rt
