// SPDX-License-Identifier: Apache-2.0
// BSDF tests: sampling against evaluation (chi-square), sample weights, reciprocity and energy conservation.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include "reference_tracer/bsdf.h"
#include "tests/reference_tracer/lobe_albedo.h"

namespace ct::rt {
namespace {


Vec3 direction_with_cos(double cos_theta, double phi = 0.3) {
  const double s = std::sqrt(1.0 - cos_theta * cos_theta);
  return {s * std::cos(phi), s * std::sin(phi), cos_theta};
}

// Regularised upper incomplete gamma Q(a, x) (series for x < a + 1, Lentz's continued fraction otherwise).
double gamma_q(double a, double x) {
  if (x <= 0.0) return 1.0;
  const double log_prefix = -x + a * std::log(x) - std::lgamma(a);
  if (x < a + 1.0) {
    double sum = 1.0 / a, term = sum;
    for (int n = 1; n < 10000 && std::abs(term) > 1e-16 * std::abs(sum); ++n) {
      term *= x / (a + n);
      sum += term;
    }
    return 1.0 - sum * std::exp(log_prefix);
  }
  double b = x + 1.0 - a, c = 1e300, d = 1.0 / b, h = d;
  for (int i = 1; i < 10000; ++i) {
    const double an = -i * (i - a);
    b += 2.0;
    d = an * d + b;
    d = std::abs(d) < 1e-300 ? 1e-300 : d;
    c = b + an / c;
    c = std::abs(c) < 1e-300 ? 1e-300 : c;
    d = 1.0 / d;
    const double delta = d * c;
    h *= delta;
    if (std::abs(delta - 1.0) < 1e-15) break;
  }
  return std::exp(log_prefix) * h;
}

TEST(ChiSquareHelper, IncompleteGammaMatchesKnownValues) {
  // Q(1, x) = e^{-x}; Q(k/2, x/2) is the chi-square survival function: P(χ²₁₀ > 18.307) = 0.05.
  EXPECT_NEAR(gamma_q(1.0, 2.0), std::exp(-2.0), 1e-12);
  EXPECT_NEAR(gamma_q(5.0, 18.307 / 2.0), 0.05, 1e-4);
  EXPECT_NEAR(gamma_q(50.0, 124.342 / 2.0), 0.05, 1e-4);  // χ²₁₀₀
}

// Chi-square test of a lobe's sampling against its pdf: histogram N samples over (cos θ, φ) bins of the
// upper hemisphere and compare with N·∫_bin pdf dω (composite Gauss–Legendre in each bin). Bins expecting
// fewer than 5 samples are pooled. Returns the p-value.
template <class Lobe>
double chi_square_p_value(const Lobe& lobe, const Vec3& wo, std::uint64_t seed) {
  constexpr int kCos = 20, kPhi = 40, kSamples = 400000;
  std::vector<double> observed(kCos * kPhi, 0.0), expected(kCos * kPhi, 0.0);
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> uni(0.0, 1.0);
  for (int i = 0; i < kSamples; ++i) {
    const auto s = lobe.sample(wo, Vec2(uni(rng), uni(rng)));
    if (!s) continue;
    const int ci = std::min(kCos - 1, static_cast<int>(s->wi.z() * kCos));
    double phi = std::atan2(s->wi.y(), s->wi.x());
    if (phi < 0) phi += 2 * std::numbers::pi;
    const int pi = std::min(kPhi - 1, static_cast<int>(phi / (2 * std::numbers::pi) * kPhi));
    observed[ci * kPhi + pi] += 1.0;
  }
  static constexpr double gx[5] = {-0.9061798459386640, -0.5384693101056831, 0.0, 0.5384693101056831,
                                   0.9061798459386640};
  static constexpr double gw[5] = {0.2369268850561891, 0.4786286704993665, 0.5688888888888889,
                                   0.4786286704993665, 0.2369268850561891};
  constexpr int kSub = 8;
  for (int ci = 0; ci < kCos; ++ci)
    for (int pi = 0; pi < kPhi; ++pi) {
      const double c0 = double(ci) / kCos, dc = 1.0 / kCos / kSub;
      const double p0 = 2 * std::numbers::pi * pi / kPhi, dp = 2 * std::numbers::pi / kPhi / kSub;
      double integral = 0.0;
      for (int a = 0; a < kSub; ++a)
        for (int b = 0; b < kSub; ++b)
          for (int i = 0; i < 5; ++i)
            for (int j = 0; j < 5; ++j) {
              const double c = c0 + (a + 0.5 + 0.5 * gx[i]) * dc;
              const double phi = p0 + (b + 0.5 + 0.5 * gx[j]) * dp;
              const double s = std::sqrt(std::max(0.0, 1.0 - c * c));
              // dω = d(cos θ) dφ
              integral += 0.25 * gw[i] * gw[j] * dc * dp * lobe.pdf(wo, Vec3(s * std::cos(phi), s * std::sin(phi), c));
            }
      expected[ci * kPhi + pi] = integral * kSamples;
    }
  double chi2 = 0.0, pooled_obs = 0.0, pooled_exp = 0.0;
  int dof = -1;
  for (std::size_t i = 0; i < observed.size(); ++i) {
    if (expected[i] < 5.0) {
      pooled_obs += observed[i];
      pooled_exp += expected[i];
      continue;
    }
    chi2 += (observed[i] - expected[i]) * (observed[i] - expected[i]) / expected[i];
    ++dof;
  }
  if (pooled_exp >= 5.0) {
    chi2 += (pooled_obs - pooled_exp) * (pooled_obs - pooled_exp) / pooled_exp;
    ++dof;
  } else if (pooled_obs > 20.0) {
    return 0.0;  // samples where the pdf says there should be almost none
  }
  return gamma_q(0.5 * dof, 0.5 * chi2);
}

// Šidák-corrected significance over every chi-square test in this file (3 lobes × 3 parameters × 3 angles
// + Lambert × 3): a correct sampler fails one of them with probability 1 %.
constexpr int kChiSquareTests = 30;
const double kSignificance = 1.0 - std::pow(0.99, 1.0 / kChiSquareTests);

TEST(Lambert, SamplingMatchesPdf) {
  for (double c : {0.2, 0.6, 0.95}) EXPECT_GT(chi_square_p_value(LambertLobe{}, direction_with_cos(c), 1), kSignificance);
}

TEST(Ggx, SamplingMatchesPdf) {
  for (double alpha : {0.1, 0.3, 0.7})
    for (double c : {0.2, 0.6, 0.95})
      EXPECT_GT(chi_square_p_value(GgxLobe{alpha}, direction_with_cos(c), 2), kSignificance)
          << "alpha " << alpha << " cos " << c;
}

TEST(Phong, SamplingMatchesPdf) {
  for (double n : {2.0, 20.0, 80.0})
    for (double c : {0.2, 0.6, 0.95})
      EXPECT_GT(chi_square_p_value(PhongLobe{n}, direction_with_cos(c), 3), kSignificance) << "n " << n << " cos " << c;
}

// Every sampled direction's weight must be eval / pdf of that direction, or the estimator is biased.
template <class Lobe>
void expect_weights_match_eval(const Lobe& lobe, const std::string& name) {
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> uni(0.0, 1.0);
  for (double c : {0.1, 0.5, 0.9}) {
    const Vec3 wo = direction_with_cos(c, 1.1);
    for (int i = 0; i < 2000; ++i) {
      const auto s = lobe.sample(wo, Vec2(uni(rng), uni(rng)));
      if (!s) continue;
      ASSERT_NEAR(s->pdf, lobe.pdf(wo, s->wi), 1e-9 * s->pdf) << name;
      ASSERT_NEAR(s->weight, lobe.eval(wo, s->wi) / s->pdf, 1e-9 * s->weight) << name;
    }
  }
}

TEST(Lobes, SampleWeightsAreEvalOverPdf) {
  expect_weights_match_eval(LambertLobe{}, "lambert");
  for (double a : {0.05, 0.3, 1.0}) {
    expect_weights_match_eval(GgxLobe{a}, "ggx");
    expect_weights_match_eval(GgxLobe{a, true}, "ggx, height-correlated");
  }
  for (double n : {1.0, 30.0, 500.0}) expect_weights_match_eval(PhongLobe{n}, "phong");
}

TEST(Lobes, AreReciprocal) {
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> uni(0.05, 0.99);
  for (int i = 0; i < 200; ++i) {
    const Vec3 a = direction_with_cos(uni(rng), 6 * uni(rng)), b = direction_with_cos(uni(rng), 6 * uni(rng));
    // eval includes cos θi, so f(a, b) = eval(a, b) / cos θb.
    for (const GgxLobe ggx : {GgxLobe{0.4}, GgxLobe{0.4, true}})
      EXPECT_NEAR(ggx.eval(a, b) / b.z(), ggx.eval(b, a) / a.z(), 1e-12 * (1 + ggx.eval(a, b) / b.z()));
    const PhongLobe phong{15};
    EXPECT_NEAR(phong.eval(a, b) / b.z(), phong.eval(b, a) / a.z(), 1e-12 * (1 + phong.eval(a, b) / b.z()));
  }
}

// Directional albedo ∫ f cos θi dωi = E[weight] over the lobe's own samples. It must not exceed 1 for any
// incidence angle and roughness; the estimate's standard error sets the tolerance (4 σ).
template <class Lobe>
void expect_energy_conserving(const Lobe& lobe, const std::string& name) {
  for (double c : {0.02, 0.1, 0.3, 0.5, 0.7, 0.9, 1.0}) {
    const test::AlbedoEstimate a = test::directional_albedo(lobe, direction_with_cos(c), 100000, 17);
    EXPECT_LE(a.mean, 1.0 + 4.0 * a.se + 1e-12) << name << " at cos θo = " << c;
  }
}

TEST(Lobes, ConserveEnergy) {
  expect_energy_conserving(LambertLobe{}, "lambert");
  for (double roughness : {0.01, 0.1, 0.3, 0.5, 0.8, 1.0}) {
    expect_energy_conserving(GgxLobe{roughness * roughness}, "ggx");
    expect_energy_conserving(GgxLobe{roughness * roughness, true}, "ggx, height-correlated");
  }
  for (double n : {0.0, 1.0, 10.0, 100.0, 1000.0}) expect_energy_conserving(PhongLobe{n}, "phong");
}

// Height-correlated masking 1 / (1 + Λo + Λi) never shadows more than the separable G1(wo)·G1(wi) =
// 1 / (1 + Λo + Λi + Λo·Λi), and equals it where either Λ is 0: at normal incidence, and as alpha → 0.
TEST(Ggx, HeightCorrelatedMaskingBoundsTheSeparableOneAndMeetsItWhereItMust) {
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> uni(0.02, 1.0);
  for (int i = 0; i < 500; ++i) {
    const Vec3 wo = direction_with_cos(uni(rng), 6 * uni(rng)), wi = direction_with_cos(uni(rng), 6 * uni(rng));
    const GgxLobe separable{0.6}, correlated{0.6, true};
    const double lo = separable.Lambda(wo), li = separable.Lambda(wi);
    EXPECT_NEAR(correlated.G2(wo, wi), 1 / (1 + lo + li), 1e-12);
    EXPECT_NEAR(separable.G2(wo, wi), 1 / ((1 + lo) * (1 + li)), 1e-12);
    EXPECT_GE(correlated.G2(wo, wi), separable.G2(wo, wi));
    const Vec3 normal(0, 0, 1);
    EXPECT_NEAR(correlated.G2(normal, wi), separable.G2(normal, wi), 1e-15);
    const GgxLobe smooth_correlated{1e-4, true}, smooth_separable{1e-4};
    EXPECT_NEAR(smooth_correlated.G2(wo, wi), smooth_separable.G2(wo, wi), 1e-6);
  }
}

TEST(Ggx, NormalDistributionIsNormalised) {
  // ∫ D(h) cos θh dωh = 1 (the projected microfacet area equals the macro-surface).
  for (double alpha : {0.05, 0.2, 0.6, 1.0}) {
    const GgxLobe ggx{alpha};
    // Substitute cos θ = c; ∫₀¹ 2π D(c) c dc with a fine midpoint rule near the peak.
    const int n = 2000000;
    double sum = 0.0;
    for (int i = 0; i < n; ++i) {
      const double c = (i + 0.5) / n;
      sum += 2 * std::numbers::pi * ggx.D(direction_with_cos(c)) * c / n;
    }
    EXPECT_NEAR(sum, 1.0, 1e-4) << alpha;
  }
}

TEST(Lambert, AlbedoIsExactlyOne) {
  const LambertLobe l;
  for (double c : {0.1, 0.7}) {
    const auto s = l.sample(direction_with_cos(c), Vec2(0.3, 0.8));
    ASSERT_TRUE(s);
    EXPECT_DOUBLE_EQ(s->weight, 1.0);
  }
}

TEST(Mirror, ReflectsAboutTheNormal) {
  const auto s = MirrorLobe{}.sample(Vec3(0.6, 0.0, 0.8), Vec2(0.5, 0.5));
  ASSERT_TRUE(s);
  EXPECT_TRUE(s->wi.isApprox(Vec3(-0.6, 0.0, 0.8)));
  EXPECT_EQ(s->weight, 1.0);
}

TEST(Frame, IsOrthonormal) {
  std::mt19937_64 rng(3);
  std::normal_distribution<double> g;
  for (int i = 0; i < 1000; ++i) {
    const Vec3 n = Vec3(g(rng), g(rng), g(rng)).normalized();
    const Frame f(n);
    EXPECT_NEAR(f.s.dot(f.t), 0.0, 1e-12);
    EXPECT_NEAR(f.s.dot(f.n), 0.0, 1e-12);
    EXPECT_NEAR(f.s.norm(), 1.0, 1e-12);
    EXPECT_NEAR(f.t.norm(), 1.0, 1e-12);
    EXPECT_TRUE(f.to_world(f.to_local(n)).isApprox(n, 1e-12));
  }
}

}  // namespace
}  // namespace ct::rt
